"""Predictors: features in, motion case and future position out."""
