"""The simulator's `monopic` commands: record, sweep, report, dataset, closed-loop.

Each module's `register(subparsers)` is listed in the `monopic.commands` entry-point
group (pyproject.toml), which the one `monopic` command reads: the pipeline never
imports the simulator, and another package adds its commands the same way.
"""
