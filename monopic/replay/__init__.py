"""Replaying logged tracks in the authors' CSV format through our stages, and scoring them."""
