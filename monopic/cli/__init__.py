"""Command-line layer: the only place that may join the pipeline with the simulator."""
