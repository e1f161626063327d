"""The motion manifold: a denoising convolutional autoencoder of motion windows (Holden et al.; Yearsley §3.1.1)."""
