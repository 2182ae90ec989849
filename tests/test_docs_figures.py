"""Figures the READMEs quote about the shipped sweeps agree with the specs and each other."""

from __future__ import annotations

import re

import pytest

from sim.runs.sweep import expand_spec, load_spec
from tests.paths import ROOT, SCENARIOS

SCENARIOS_README = (SCENARIOS / "README.md").read_text()
README = (ROOT / "README.md").read_text()


@pytest.mark.parametrize("name", ["demo", "medium", "large"])
def test_the_run_counts_in_scenarios_readme_are_the_specs_own(name: str) -> None:
    (count,) = re.findall(rf"{name}\.toml \((\d+) runs", SCENARIOS_README)
    assert int(count) == len(expand_spec(load_spec(SCENARIOS / "sweeps" / f"{name}.toml")))


def test_both_readmes_quote_the_same_sweep_times_and_sizes() -> None:
    minutes = re.findall(r"(\d+) min\s+on 2 cores", SCENARIOS_README)
    assert len(minutes) == 2
    (readme_medium,) = re.findall(r"medium\.toml` \(518 runs, about (\d+) min on 2 cores", README)
    (readme_large,) = re.findall(r"large\.toml` \((\d+) runs, about (\d+) min", README)
    assert minutes == [readme_medium, readme_large[1]]
    (large,) = re.findall(r"large\.toml \((\d+) runs", SCENARIOS_README)
    assert large == readme_large[0]
