"""The simulated world: street, mannequin, robot, pedestrian, scene, renderer, World.step, truth.

MuJoCo draws it, highway-env moves the robot and the pedestrian; `world.World` steps
both and returns what the camera saw, the robot's own state and the ground truth.
"""
