"""Which ground-motion estimator should the warning's track be? Replayed on sweeps' own runs."""
