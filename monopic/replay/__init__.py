"""The image-mode tree on the authors' logs: their CSV format read strictly, each row's
features and labels, the tree trained on some logs and judged on another, and any
predictor replayed through our stages and scored (`monopic replay`, `monopic tree train`
in image mode, `monopic tree judge`).

The ground intent tree trains on the simulator's datasets instead: monopic.tree.intent_training.
"""
