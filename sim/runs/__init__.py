"""Running scenarios: the pipelines compared, one run, the closed loop, sweeps and results files."""
