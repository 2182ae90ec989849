"""The `monopic` command and the pipeline's own sub-commands (video, tree, replay, view).

monopic.cli.main builds the command from the `monopic.commands` entry-point group
(pyproject.toml): these modules register the pipeline's sub-commands there, sim.commands
the simulator's, so the pipeline never imports the simulator.
"""
