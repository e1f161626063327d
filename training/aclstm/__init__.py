"""The dance models (acLSTM and its vanilla baseline): training, export, evaluation."""
