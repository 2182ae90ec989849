"""Frames and shapes the simulator shares: world and highway-env frames, ground polygons."""
