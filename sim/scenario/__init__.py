"""What a run is: the Scenario record and the path it implies, scenario files, families, cases.

Plain data and maths only: nothing here imports MuJoCo, highway-env or gymnasium.
"""
