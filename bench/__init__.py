"""The benchmarks: what `make bench` runs (bench/Makefile.bench) and what makes the rows of
BENCHMARKS.md, each script's docstring saying what it measures.

Every script runs as a module from the checkout's top folder, `.venv/bin/python -m
bench.pipeline_latency`, and imports its neighbours as `bench.history`; a run appends its
line to bench/history.jsonl (bench/recorder.py) and BENCHMARKS.md is rendered from that
history (bench/render.py). Not part of the product: monopic and sim import nothing from
here. The reference workers (reference_worker, worker_common, frameset) also run in
.venv-reference, which has MediaPipe and not the project: they import only numpy, the
standard library and monopic's pure-Python modules, found from the top folder.
"""
