"""Motion Playground training package: mocap loaders, datasets, models, training, export, evaluation."""
