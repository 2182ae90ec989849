"""The ID3 decision tree: learner, discretisers, the trained model as a predictor.

The default image-mode tree ships as default_tree.json (see DEFAULT_TREE.md).
"""
