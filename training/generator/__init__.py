"""The locomotion generator (LSTM + Gaussian mixture): training, export, evaluation, recovery."""
