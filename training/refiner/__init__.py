"""The adversarial refiner: training, export, evaluation."""
