"""MonoPIC: where will the pedestrian seen by one camera be a second from now.

Data flows one way: frame -> pose -> features -> predictor -> warning -> overlay/log.
"""

__version__ = "0.1.0"
