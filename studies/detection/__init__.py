"""In what share of rendered frames does the pose tracker find the walker?"""
