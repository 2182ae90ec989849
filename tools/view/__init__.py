"""Recordings as the real rerun viewer draws them, on a machine without a display."""
