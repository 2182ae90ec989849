"""Motion features from pose landmarks: orientation, image velocity, ground motion."""
