"""The simulator's `monopic` sub-commands, one module each.

Each module's `register(subparsers)` is listed in the `monopic.commands` entry-point
group (pyproject.toml, which names them all), which the one `monopic` command reads: the
pipeline never imports the simulator, and another package adds its commands the same way.
"""
