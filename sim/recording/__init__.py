"""Rerun recordings of simulated runs: camera, pipeline, truth and world, frame by frame."""
