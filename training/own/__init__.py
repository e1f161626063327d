"""Training on your own motion: python -m training.own turns a folder of BVH or ASF/AMC files on any humanoid
skeleton into a model pack (docs/training.md, "Train on your own motion")."""
