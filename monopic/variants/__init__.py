"""The paper's three ways to use a prediction: collision warning, path projection, direction."""
