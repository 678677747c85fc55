"""The seeded fuzzer of the g2o loader and boxplus-g2o (harness.fuzz):
10⁴ mutated files in-process (and a sample through the CLI) must all end as
ok or as an error naming the file (and line); the inputs of earlier bad
outcomes, kept in tests/data/fuzz_regressions/, are replayed."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import pytest
from harness import boxplus_g2o, fuzz

DATA = Path(__file__).resolve().parents[1] / "data"
REGRESSIONS = DATA / "fuzz_regressions"


_cli = boxplus_g2o


def test_ten_thousand_seeded_cases_end_ok_or_named(tmp_path):
    counts, bad = fuzz.run(10_000, seed=1, data=DATA, cli=_cli(), cli_every=100,
                           regressions=tmp_path / "new_regressions")
    assert sum(counts.values()) == 10_000
    assert not bad, f"{dict(counts)}; first: {bad[:5]}"
    # The corpus exercises both sides: accepted graphs and refused ones.
    assert counts["ok"] > 1000 and counts["parse_error"] > 1000


def test_parallel_chunks_give_the_serial_outcomes(tmp_path):
    # make fuzz runs its chunks on every core: the same cases, the same outcomes
    serial = fuzz.run(600, seed=4, data=DATA, chunk=150, regressions=None)
    parallel = fuzz.run(600, seed=4, data=DATA, chunk=150, regressions=None, jobs=2)
    assert serial == parallel and sum(serial[0].values()) == 600


def test_the_fuzzer_classifies_a_crash_and_keeps_its_input(tmp_path):
    # A worker that dies is a crash, named by its case; nothing else is lost.
    name, data, options = fuzz.make_case(1, 3, fuzz.seeds(DATA))
    assert fuzz.make_case(1, 3, fuzz.seeds(DATA)) == (name, data, options)  # deterministic
    p = fuzz._save_regression(tmp_path, data, options, "crash", "test")
    assert p.read_bytes() == data
    assert json.loads(p.with_suffix(".json").read_text())["options"] == options


REGRESSION_FILES = sorted(REGRESSIONS.glob("*.g2o"))


@pytest.mark.parametrize("path", REGRESSION_FILES, ids=[p.name for p in REGRESSION_FILES])
def test_fuzz_regressions_replay_ok_or_named(path):
    options = json.loads(path.with_suffix(".json").read_text())["options"]
    with tempfile.TemporaryDirectory() as d:
        for outcome, detail in (fuzz.run_case(path.read_bytes(), options, d),
                                fuzz.run_cli_case(_cli(), path.read_bytes(), options, d)):
            assert outcome not in fuzz.BAD, detail
