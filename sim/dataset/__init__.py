"""Synthetic datasets: specs, runs rendered into images, masks, COCO keypoints; the test clip."""
