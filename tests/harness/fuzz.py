"""A seeded mutation fuzzer for the g2o/TORO loader, the pose graph and the CLI.

Each case mutates one seed file (the repository's ``tests/data/*.g2o``, cut to
small sub-graphs, and small generated graphs of every tag) with one to three
mutations — byte flips, deleted or duplicated tokens and lines, swapped tags,
NaN/inf/huge numbers, bad ids, non-PD information, zero or huge quaternions,
gimbal-lock Euler angles, huge angles, truncation, CRLF, binary junk, empty or
comment-only files — and loads it in-process through
``boxplus.slam.load_g2o`` with random options. The outcome is classified:

``ok``
    accepted, solved a few iterations, chi2 finite and equal to the independent
    numpy evaluation (``harness.g2o_reference``) where its tags allow,
    save-and-reload equal;
``parse_error``
    ``boxplus.ParseError`` naming ``file:line``;
``named_error``
    an error naming the file where no line exists (an empty file, a graph
    without poses);
``crash``
    the worker process died (signal or abort);
``hang``
    a case took longer than the time limit;
``unnamed_error``
    any other exception, or an error that does not name the file;
``wrong_load``
    accepted but the loaded graph breaks an invariant (a non-unit quaternion,
    an angle outside [−π, π), chi2 or poses that differ from the oracle or
    after save-and-reload);
``non_finite``
    accepted, but chi2 or the estimate is not finite.

The first four of the last five are failures: the input is written to
``tests/data/fuzz_regressions/`` (replayed by tests/python/test_slam_fuzz.py).
Cases run in worker subprocesses so that a crash is caught and named.

    PYTHONPATH=tests python -m harness.fuzz --cases 1000000 --seed 1
    PYTHONPATH=tests python -m harness.fuzz --cases 1000000 --minutes 60 --cli build/cpp/boxplus-g2o
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

from boxplus import _core

OUTCOMES = ("ok", "parse_error", "named_error", "crash", "hang", "unnamed_error",
            "wrong_load", "non_finite")
BAD = ("crash", "hang", "unnamed_error", "wrong_load", "non_finite")
HANG_SECONDS = 10.0
TESTS = Path(__file__).resolve().parents[1]  # the repository's tests/: seeds and regressions


def _worker_env() -> dict:
    """The environment of a worker subprocess: this harness importable from anywhere."""
    path = os.environ.get("PYTHONPATH", "")
    return {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (str(TESTS), path) if p)}

# Every tag the reader accepts, from its own table, and one it does not.
TAGS = [tag for tag, _, _ in _core.g2o_record_tags()] + ["BOGUS"]
NUMBERS = ["nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e200", "1e16", "1e-320",
           "-0", "0", "1", "-1", "1.5", "3.14159265358979", "1.5707963267948966",
           "-1.5707963267948966", "2147483648", "-2147483649", "0x10", "1e", "--1", ""]


# -- seeds -----------------------------------------------------------------


def _generated_seeds() -> dict:
    """Small graphs with every tag the reader knows (exact measurements)."""
    g2d = """VERTEX_SE2 0 0 0 0
VERTEX_SE2 1 1 0 0.1
VERTEX_SE2 2 2 0.1 0.2
VERTEX_XY 10 1 1
EDGE_SE2 0 1 1 0 0.1 100 0 0 100 0 1000
EDGE_SE2 1 2 1 0.1 0.1 100 0 0 100 0 1000
EDGE_SE2 0 2 2 0.1 0.2 100 0 0 100 0 1000
EDGE_SE2_XY 0 10 1 1 10 0 10
EDGE_SE2_XY 1 10 0 1 10 0 10
EDGE_SE2_BEARING_RANGE 2 10 2.1 1.3 100 0 10
FIX 0
"""
    g3d = """VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1
VERTEX_SE3:QUAT 1 1 0 0 0 0 0.0998 0.995
VERTEX_SE3:QUAT 2 2 0.1 0 0 0.0998 0 0.995
VERTEX_TRACKXYZ 10 1 1 1
PARAMS_SE3OFFSET 0 0 0 0 0 0 0 1
EDGE_SE3:QUAT 0 1 1 0 0 0 0 0.0998 0.995 100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400
EDGE_SE3:QUAT 1 2 1 0.1 0 0 0.0998 0 0.995 100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400
EDGE_SE3_TRACKXYZ 0 10 0 1 1 1 10 0 0 10 0 10
EDGE_SE3_TRACKXYZ 2 10 0 -1 0.9 1 10 0 0 10 0 10
FIX 0
"""
    toro2d = """VERTEX2 0 0 0 0
VERTEX2 1 1 0 0.1
VERTEX2 2 2 0.1 3.1
EDGE2 0 1 1 0 0.1 100 0 100 1000 0 0
EDGE2 1 2 1 0.1 3.0 100 0 100 1000 0 0
"""
    toro3d = """VERTEX3 0 0 0 0 0 0 0
VERTEX3 1 1 0 0 0.3 1.5707963267948966 0.5
VERTEX3 2 2 0 0 0.1 -1.5707963267948966 -0.2
EDGE3 0 1 1 0 0 0.3 1.5707963267948966 0.5 100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400
EDGE3 1 2 1 0 0 0.2 -0.5 0.1 100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400
"""
    no_vertices = """EDGE_SE2 0 1 1 0 0.1 100 0 0 100 0 1000
EDGE_SE2 1 2 1 0 0.1 100 0 0 100 0 1000
EDGE_SE2 2 0 -2 0 -0.2 100 0 0 100 0 1000
"""
    return {"gen2d.g2o": g2d, "gen3d.g2o": g3d, "toro2d.graph": toro2d,
            "toro3d.graph": toro3d, "novertex.g2o": no_vertices}


def _cut(text: str, max_vertices: int) -> str:
    """The first vertices of a file and the edges among them (edges only, when
    the file has no vertices: the first few)."""
    lines = text.splitlines(keepends=True)
    keep: list[str] = []
    ids: set[int] = set()
    for ln in lines:
        t = ln.split()
        if t and t[0].startswith("VERTEX") and len(ids) < max_vertices:
            try:
                ids.add(int(t[1]))
            except (ValueError, IndexError):
                continue
            keep.append(ln)
    if not ids:
        return "".join(lines[: 3 * max_vertices])
    for ln in lines:
        t = ln.split()
        if t and t[0].startswith("EDGE"):
            try:
                a, b = int(t[1]), int(t[2])
            except (ValueError, IndexError):
                continue
            if a in ids and b in ids:
                keep.append(ln)
        elif t and t[0] == "FIX":
            keep.append(ln)
    return "".join(keep)


def seeds(data_dir: Path) -> list:
    """(name, bytes) of the seed corpus, in a fixed order."""
    out = [(n, t.encode()) for n, t in sorted(_generated_seeds().items())]
    for p in sorted(Path(data_dir).glob("*.g2o")):
        text = p.read_text(errors="replace")
        out.append((p.name, text.encode()))
        for k in (4, 12):
            out.append((f"{p.stem}-{k}.g2o", _cut(text, k).encode()))
    return out


# -- mutations ---------------------------------------------------------------


def _tokens(line: bytes) -> list:
    return line.split()


def _mutate_line_tokens(rng: random.Random, lines: list, fn) -> None:
    idx = [i for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith(b"#")]
    if not idx:
        return
    i = rng.choice(idx)
    t = _tokens(lines[i])
    t = fn(t)
    lines[i] = b" ".join(t) + b"\n"


def mutate(rng: random.Random, data: bytes) -> bytes:
    kind = rng.randrange(22)
    if kind == 0 and data:  # byte flip
        b = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        return bytes(b)
    if kind == 1:  # truncation
        return data[: rng.randrange(len(data) + 1)]
    if kind == 2:  # CRLF
        return data.replace(b"\n", b"\r\n")
    if kind == 3:  # binary junk
        pos = rng.randrange(len(data) + 1)
        junk = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        return data[:pos] + junk + data[pos:]
    if kind == 4:  # empty or comment-only
        return rng.choice([b"", b"\n\n", b"# nothing here\n", b"   \t\n# x\n"])
    lines = data.splitlines(keepends=True) or [b"\n"]
    if kind == 5:  # delete a token
        _mutate_line_tokens(rng, lines, lambda t: t[:k] + t[k + 1:] if (k := rng.randrange(len(t))) >= 0 else t)
    elif kind == 6:  # duplicate a token
        _mutate_line_tokens(rng, lines, lambda t: t[:k] + [t[k]] + t[k:] if (k := rng.randrange(len(t))) >= 0 else t)
    elif kind == 7:  # swap the tag
        _mutate_line_tokens(rng, lines, lambda t: [rng.choice(TAGS).encode()] + t[1:])
    elif kind in (8, 9):  # special numbers
        def special(t):
            if len(t) > 1:
                t[rng.randrange(1, len(t))] = rng.choice(NUMBERS).encode()
            return t
        _mutate_line_tokens(rng, lines, special)
    elif kind == 10:  # bad ids
        def bad_id(t):
            if len(t) > 2:
                t[rng.randint(1, 2)] = str(rng.choice([-1, 999999, 2**31, 10, 0, 1, 2])).encode()
            return t
        _mutate_line_tokens(rng, lines, bad_id)
    elif kind == 11:  # non-PD information: a diagonal entry ≤ 0 or a huge off-diagonal
        def non_pd(t):
            if len(t) > 8 and t[0].startswith(b"EDGE"):
                t[-1] = rng.choice([b"0", b"-1", b"-1e300"])
                if rng.random() < 0.5:
                    t[-2] = b"1e300"
            return t
        _mutate_line_tokens(rng, lines, non_pd)
    elif kind == 12:  # quaternions: zero, huge, tiny
        def quat(t):
            if t[0] in (b"VERTEX_SE3:QUAT", b"PARAMS_SE3OFFSET") and len(t) >= 9:
                q0 = 5
            elif t[0] == b"EDGE_SE3:QUAT" and len(t) >= 10:
                q0 = 6
            else:
                return t
            choice = rng.randrange(3)
            vals = ([b"0"] * 4 if choice == 0 else
                    [b"0", b"0", b"0", b"1e200"] if choice == 1 else
                    [b"1e-200", b"0", b"0", b"1e-200"])
            rng.shuffle(vals)
            t[q0:q0 + 4] = vals
            return t
        _mutate_line_tokens(rng, lines, quat)
    elif kind == 13:  # delete a line
        del lines[rng.randrange(len(lines))]
    elif kind == 14:  # duplicate a line
        k = rng.randrange(len(lines))
        lines.insert(rng.randrange(len(lines) + 1), lines[k])
    elif kind == 15:  # FIX of some id
        lines.append(f"FIX {rng.choice([0, 1, 2, 3, 10, -5, 99999])}\n".encode())
    elif kind == 16:  # huge SE2 angle
        def angle(t):
            if t[0] in (b"VERTEX_SE2", b"VERTEX2") and len(t) >= 5:
                t[4] = rng.choice([b"1e16", b"-1e16", b"1e300", b"7", b"-3.1415926535897931"])
            return t
        _mutate_line_tokens(rng, lines, angle)
    elif kind == 17:  # gimbal-lock Euler angles
        def euler(t):
            if t[0] in (b"VERTEX3",) and len(t) >= 8:
                t[6] = rng.choice([b"1.5707963267948966", b"-1.5707963267948966"])
            elif t[0] == b"EDGE3" and len(t) >= 9:
                t[7] = rng.choice([b"1.5707963267948966", b"-1.5707963267948966"])
            return t
        _mutate_line_tokens(rng, lines, euler)
    elif kind == 18:  # a random number
        def num(t):
            if len(t) > 1:
                t[rng.randrange(1, len(t))] = repr(rng.uniform(-1e3, 1e3)).encode()
            return t
        _mutate_line_tokens(rng, lines, num)
    elif kind == 19:  # swap two lines
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif kind == 20:  # bearing-range with a negative range
        lines.append(b"EDGE_SE2_BEARING_RANGE 0 10 0.5 -1 10 0 10\n")
    else:  # non-UTF-8 bytes inside a token
        _mutate_line_tokens(rng, lines, lambda t: t[:1] + [b"\xff\xfe\xc3("] + t[1:])
    return b"".join(lines)


def make_case(seed: int, index: int, corpus: list) -> tuple:
    """(name, data, options) of case `index` of the run with `seed` (deterministic)."""
    rng = random.Random(f"{seed}:{index}")
    name, data = corpus[rng.randrange(len(corpus))]
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        data = mutate(rng, data)
    options = {
        "init": rng.choice(["file", "file", "spanning-tree", "chordal"]),
        "convention": rng.choice(["g2o", "g2o", "log", "sesync"]),
        "skip_unknown": rng.random() < 0.3,
        "repair_information": rng.random() < 0.3,
    }
    return name, data, options


# -- one case ----------------------------------------------------------------


def _finite(x) -> bool:
    import numpy as np

    return bool(np.all(np.isfinite(np.asarray(x, float))))


def _oracle_tags(text: bytes) -> bool:
    ok = {b"VERTEX_SE2", b"EDGE_SE2", b"VERTEX_SE3:QUAT", b"EDGE_SE3:QUAT"}
    for ln in text.splitlines():
        t = ln.split()
        if t and not t[0].startswith(b"#") and t[0] not in ok:
            return False
    return True


def _close(a: float, b: float) -> bool:
    # Beyond 1e15 both evaluations have lost their digits to the cancellation
    # in x_i⁻¹ x_j of huge coordinates: only their finiteness is compared.
    if min(abs(a), abs(b)) > 1e15:
        return math.isfinite(a) == math.isfinite(b)
    return abs(a - b) <= 1e-7 * max(1.0, abs(a), abs(b))


def _numbers_well_scaled(text: bytes) -> bool:
    """Whether χ² of a graph can be compared digit by digit between two correct
    evaluations: not when a number of the file exceeds 1e15. An information
    entry that large times a last-bit change (a re-normalised quaternion, an
    angle) moves χ² arbitrarily (a 1e308 entry: 1.2e276 before a save, 1.7e-10
    after, both correct); a coordinate or measurement that large leaves an
    absolute rounding of ≥ 1 in xᵢ⁻¹xⱼ (a 1e16 m measurement: χ² 452.8 against
    the oracle's 584.9)."""
    for line in text.splitlines():
        for token in line.split()[1:]:
            try:
                if abs(float(token)) > 1e15:
                    return False
            except ValueError:
                continue
    return True


def _estimates_from_file(g) -> bool:
    rep = g.report
    return rep["estimates_from_file"] if isinstance(rep, dict) else rep.estimates_from_file


def check_graph(g, path: str, data: bytes, options: dict) -> tuple:
    """Invariants of an accepted graph; ('ok', '') or (outcome, detail)."""
    import warnings

    import boxplus.slam as slam
    import numpy as np

    from harness import g2o_reference as ref

    poses = g.poses()
    if not _finite(poses) or not _finite(g.landmarks()):
        return "non_finite", "loaded estimate is not finite"
    if g.dimension == 3 and len(poses):
        if np.max(np.abs(np.linalg.norm(poses[:, 3:], axis=1) - 1)) > 1e-9:
            return "wrong_load", "a quaternion is not unit"
    if g.dimension == 2 and len(poses):
        if np.any(poses[:, 2] < -math.pi - 1e-12) or np.any(poses[:, 2] > math.pi + 1e-12):
            return "wrong_load", "an angle outside [-pi, pi]"
    chi0 = g.chi2()
    if not math.isfinite(chi0):
        # An infinite objective at the start (a bearing to a point on the
        # pose) is legal only if the solver then refuses to run.
        pass
    # The oracle reads the file's own information matrices: a graph whose
    # matrices were repaired is compared after it is saved (below), not here.
    if (options["init"] == "file" and options["convention"] == "g2o" and _oracle_tags(data)
            and _estimates_from_file(g) and g.num_edges and g.report.repaired_information == 0):
        d = ref.read_g2o_arrays(path)
        r = ref.chi2_g2o(d, d["poses"])
        if math.isfinite(r) and _numbers_well_scaled(data) and not (math.isfinite(chi0) and _close(chi0, r)):
            return "wrong_load", f"chi2 {chi0} differs from the numpy evaluation {r}"
    summary = g.solve(max_iterations=3)
    chi = g.chi2()
    if summary.usable and not (math.isfinite(chi) and _finite(g.poses())):
        return "non_finite", f"solver reported usable with chi2 {chi}"
    if not math.isfinite(chi):
        return "ok", "solver refused a non-finite objective"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "out.g2o")
        g.save_g2o(out)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            h = slam.load_g2o(out, convention=options["convention"], init="file")
        saved = Path(out).read_bytes()
        if _numbers_well_scaled(saved) and not _close(h.chi2(), chi):
            return "wrong_load", f"reloaded chi2 {h.chi2()} != {chi}"
        if _oracle_tags(Path(out).read_bytes()) and options["convention"] == "g2o" and g.num_edges:
            # The saved file, read by the oracle in its own order (a file
            # without vertices gets them sorted by id when saved).
            d = ref.read_g2o_arrays(out)
            r = ref.chi2_g2o(d, d["poses"])
            if math.isfinite(r) and _numbers_well_scaled(saved) and not _close(r, chi):
                return "wrong_load", f"chi2 {chi} differs from the numpy evaluation {r}"
    return "ok", ""


def run_case(data: bytes, options: dict, workdir: str) -> tuple:
    """Loads one input in-process; returns (outcome, detail)."""
    import warnings

    import boxplus
    import boxplus.slam as slam

    path = os.path.join(workdir, "case.g2o")
    with open(path, "wb") as f:
        f.write(data)
    t0 = time.monotonic()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            g = slam.load_g2o(path, **options)
            outcome = check_graph(g, path, data, options)
    except boxplus.ParseError as e:
        msg = str(e)
        outcome = ("parse_error", "") if f"{path}:" in msg else ("unnamed_error", msg[:200])
    except Exception as e:  # noqa: BLE001 — every other exception is classified
        msg = str(e)
        named = path in msg and not isinstance(e, UnicodeError)
        outcome = ("named_error" if named else "unnamed_error", f"{type(e).__name__}: {msg[:200]}")
    if time.monotonic() - t0 > HANG_SECONDS:
        return "hang", f"{time.monotonic() - t0:.1f} s"
    return outcome


def run_cli_case(cli: str, data: bytes, options: dict, workdir: str) -> tuple:
    """Runs boxplus-g2o on one input; exit 0 with a reloadable output, or exit 2
    with a message naming the file (exit 1: the solver failed, stated)."""
    path = os.path.join(workdir, "cli.g2o")
    out = os.path.join(workdir, "cli-out.g2o")
    with open(path, "wb") as f:
        f.write(data)
    if os.path.exists(out):
        os.remove(out)
    cmd = [cli, "-i", "3", "-q", "--init", options["init"], "-c", options["convention"],
           "-o", out, path]
    if options["skip_unknown"]:
        cmd.append("--skip-unknown")
    if options["repair_information"]:
        cmd.append("--repair-information")
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=HANG_SECONDS * 3)
    except subprocess.TimeoutExpired:
        return "hang", "cli"
    err = p.stderr.decode(errors="replace")
    if p.returncode < 0:
        return "crash", f"cli signal {-p.returncode}"
    if p.returncode == 2:
        return ("parse_error", "") if f"{path}:" in err or path in err else ("unnamed_error", err[:200])
    if p.returncode in (0, 1):
        if p.returncode == 0 and not os.path.exists(out):
            return "wrong_load", "cli wrote no output"
        return "ok", ""
    return "unnamed_error", f"cli exit {p.returncode}: {err[:200]}"


# -- driver ------------------------------------------------------------------


def _worker(args) -> int:
    corpus = seeds(args.data)
    with tempfile.TemporaryDirectory() as d:
        for i in range(args.start, args.end):
            with open(args.progress, "w") as f:
                f.write(str(i))
            _, data, options = make_case(args.seed, i, corpus)
            outcome, detail = run_case(data, options, d)
            if args.cli and i % args.cli_every == 0:
                cli_outcome, cli_detail = run_cli_case(args.cli, data, options, d)
                if cli_outcome in BAD:
                    outcome, detail = cli_outcome, cli_detail
            sys.stdout.write(json.dumps([i, outcome, detail]) + "\n")
            sys.stdout.flush()
    return 0


def _save_regression(directory: Path, data: bytes, options: dict, outcome: str, detail: str) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    h = hashlib.sha1(data + json.dumps(options, sort_keys=True).encode()).hexdigest()[:12]
    p = directory / f"{outcome}-{h}.g2o"
    p.write_bytes(data)
    (directory / f"{outcome}-{h}.json").write_text(
        json.dumps({"options": options, "outcome": outcome, "detail": detail}, indent=1) + "\n")
    return p


def _chunk(seed: int, start: int, end: int, data: Path, cli: str | None, cli_every: int,
           progress: str) -> tuple:
    """Cases [start, end) in worker subprocesses: a worker that dies is a crash of
    the case after its last report, and a new worker goes on after it."""
    counts: Counter = Counter()
    bad: list = []
    while start < end:
        cmd = [sys.executable, "-m", "harness.fuzz", "--worker", "--seed", str(seed),
               "--start", str(start), "--end", str(end), "--progress", progress,
               "--data", str(data), "--cli-every", str(cli_every)]
        if cli:
            cmd += ["--cli", cli]
        last = start - 1
        with subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True, env=_worker_env()) as p:
            assert p.stdout is not None  # stdout=PIPE
            for line in p.stdout:
                i, outcome, detail = json.loads(line)
                last = i
                counts[outcome] += 1
                if outcome in BAD:
                    bad.append((i, outcome, detail))
        if last + 1 < end:  # the worker died on case last + 1
            last += 1
            counts["crash"] += 1
            bad.append((last, "crash", f"worker exit {p.returncode}"))
        start = last + 1
    return counts, bad


def run(cases: int, seed: int = 1, data: Path = Path("tests/data"), cli: str | None = None,
        cli_every: int = 200, regressions: Path | None = Path("tests/data/fuzz_regressions"),
        chunk: int = 2000, verbose: bool = False, minutes: float | None = None,
        jobs: int = 1) -> tuple:
    """Runs `cases` seeded cases in worker subprocesses, chunk by chunk, ``jobs``
    chunks at a time (or fewer cases: the chunks started within `minutes`);
    returns (Counter of outcomes, list of (index, outcome, detail) of the bad
    ones, by index). Bad inputs are saved as each chunk ends, so an interrupted
    long run keeps what it found. The outcomes do not depend on ``jobs``."""
    from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

    counts: Counter = Counter()
    bad: list = []
    corpus = seeds(data)
    t0 = time.monotonic()
    done_cases = 0
    starts = iter(range(0, cases, chunk))
    with tempfile.TemporaryDirectory() as d, ThreadPoolExecutor(max(1, jobs)) as pool:
        running: dict = {}

        def submit() -> bool:
            if minutes is not None and time.monotonic() - t0 >= 60 * minutes:
                return False
            s0 = next(starts, None)
            if s0 is None:
                return False
            e0 = min(cases, s0 + chunk)
            f = pool.submit(_chunk, seed, s0, e0, data, cli, cli_every, os.path.join(d, f"progress{s0}"))
            running[f] = (s0, e0)
            return True

        for _ in range(max(1, jobs)):
            submit()
        while running:
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for f in finished:
                s0, e0 = running.pop(f)
                c, new_bad = f.result()
                counts.update(c)
                done_cases += e0 - s0
                if regressions is not None:
                    for i, outcome, detail in new_bad:
                        _, data_i, options = make_case(seed, i, corpus)
                        _save_regression(Path(regressions), data_i, options, outcome, detail)
                bad += new_bad
                if verbose:
                    print(f"{done_cases}/{cases} {time.monotonic() - t0:.0f} s {dict(counts)}",
                          file=sys.stderr, flush=True)
                submit()
    bad.sort()
    return counts, bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--data", type=Path, default=TESTS / "data")
    ap.add_argument("--cli", default=None, help="path of boxplus-g2o (a sample of cases)")
    ap.add_argument("--cli-every", type=int, default=200)
    ap.add_argument("--chunk", type=int, default=2000)
    ap.add_argument("--minutes", type=float, default=None,
                    help="stop after the chunk that passes this wall-clock budget")
    ap.add_argument("--regressions", type=Path, default=TESTS / "data" / "fuzz_regressions")
    ap.add_argument("--no-save", action="store_true", help="do not write regression inputs")
    ap.add_argument("--jobs", type=int, default=1, help="chunks run at a time (worker processes)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--start", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--end", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--progress", default="", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        return _worker(args)
    counts, bad = run(args.cases, args.seed, args.data, args.cli, args.cli_every,
                      None if args.no_save else args.regressions, args.chunk, verbose=True,
                      minutes=args.minutes, jobs=args.jobs)
    print(json.dumps({"cases": sum(counts.values()), **{k: counts.get(k, 0) for k in OUTCOMES}}))
    for i, outcome, detail in bad[:50]:
        print(f"case {i}: {outcome}: {detail}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
