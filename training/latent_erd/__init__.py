"""The latent ERD (Yearsley Ch. 6) and its pose-space baseline: recurrent control in the motion manifold."""
