"""Scoring the pipeline's outputs against other people's ground truth (`monopic track-eval`:
multi-person tracks against MOTChallenge annotations)."""
