"""The VAE-LSTM (Habibie et al.): training, export and evaluation."""
