"""The product's tools: the shipped models made (tools/models), the shipped test clip rendered,
the cue montage drawn, recordings photographed headless (tools/view) and a restructuring's
outputs compared before and after (compare_outputs).

Run them as modules from the checkout's top folder (`.venv/bin/python -m
tools.compare_outputs ...`; tools/models under its own venv, .venv-models). Not imported by
the product: monopic and sim import nothing from here.
"""
