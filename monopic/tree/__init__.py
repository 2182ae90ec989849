"""The ID3 decision tree: learner, discretisers, the trained model as a predictor, and the
ground intent tree with its trainer (intent_training) and cue sensitivity replay.

The default image-mode tree ships as default_tree.json (see DEFAULT_TREE.md); it is trained
on the authors' logs by monopic.replay.
"""
