"""Pose-graph plots: an optional ax, the Figure returned, the backend left alone,
3D graphs in 3D, axes labelled with units."""

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from boxplus import slam

matplotlib = pytest.importorskip("matplotlib")
from matplotlib.figure import Figure  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data"


def test_2d_graph_returns_its_figure_and_draws_the_estimate():
    g = slam.load_g2o(DATA / "landmarks2d.g2o")
    before = g.positions() + 1.0
    fig = g.plot(before=before)
    try:
        assert isinstance(fig, Figure)
        (ax,) = fig.axes
        lines = {ln.get_label(): ln for ln in ax.get_lines()}
        assert set(lines) == {"before", "after", "landmarks"}
        np.testing.assert_array_equal(np.column_stack(lines["after"].get_data()), g.positions())
        np.testing.assert_array_equal(np.column_stack(lines["before"].get_data()), before)
        np.testing.assert_array_equal(np.column_stack(lines["landmarks"].get_data()), g.landmarks())
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("x [m]", "y [m]")
        assert ax.get_title() == f"chi2 = {g.chi2():.6g}"
    finally:
        matplotlib.pyplot.close(fig)


def test_into_a_given_ax_with_a_unit():
    import matplotlib.pyplot as plt

    g = slam.load_g2o(DATA / "landmarks2d.g2o")
    fig, (a, b) = plt.subplots(1, 2)
    try:
        assert g.plot(ax=b, unit="ft", title="mine") is fig
        assert len(a.get_lines()) == 0 and len(b.get_lines()) == 2
        assert b.get_xlabel() == "x [ft]" and b.get_title() == "mine"
    finally:
        plt.close(fig)


def test_3d_graph_is_drawn_in_3d_or_as_a_top_view_on_2d_axes(tmp_path):
    import matplotlib.pyplot as plt

    g = slam.load_g2o(DATA / "smallGrid3D.g2o")
    out = tmp_path / "grid.svg"
    fig = slam.plot_trajectory(g, out)
    assert out.read_text().lstrip().startswith("<?xml") and "<svg" in out.read_text()
    (ax,) = fig.axes
    assert ax.name == "3d" and ax.get_zlabel() == "z [m]"
    (after,) = [ln for ln in ax.get_lines() if ln.get_label() == "after"]
    xs, ys, zs = after.get_data_3d()
    np.testing.assert_array_equal(np.column_stack([xs, ys, zs]), g.positions())
    # A file-only figure is not registered with pyplot (no leak, no window).
    assert fig not in map(plt.figure, plt.get_fignums())
    fig2, ax2 = plt.subplots()
    try:
        g.plot(ax=ax2)
        (top,) = [ln for ln in ax2.get_lines() if ln.get_label() == "after"]
        np.testing.assert_array_equal(np.column_stack(top.get_data()), g.positions()[:, :2])
    finally:
        plt.close(fig2)
    with pytest.raises(ValueError, match=r"before: expected positions of shape \(N, 3\)"):
        g.plot(path=tmp_path / "x.png", before=np.zeros((4, 2)))


def test_plotting_never_changes_the_backend(tmp_path):
    # A fresh interpreter with the svg backend chosen by the user: it stays.
    code = textwrap.dedent(f"""
        import matplotlib
        matplotlib.use("svg")
        from boxplus import slam
        g = slam.load_g2o({str(DATA / "landmarks2d.g2o")!r})
        fig = g.plot({str(tmp_path / "a.png")!r})
        fig2 = g.plot()
        print(matplotlib.get_backend(), type(fig).__name__, type(fig2).__name__)
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["svg", "Figure", "Figure"]
    assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"


def test_loop_closures_judged_wrong_are_drawn_and_the_title_is_the_inliers(tmp_path):
    from boxplus.synthetic import pose_graphs as gen

    g = gen.generate("manhattan", 2, 300, outlier_fraction=0.2, seed=2)
    g.write(tmp_path / "g.g2o")
    graph = slam.load_g2o(tmp_path / "g.g2o")
    graph.solve()
    wrong = graph.outliers
    assert wrong
    fig = graph.plot(tmp_path / "g.png")
    try:
        (ax,) = fig.axes
        drawn = [ln for ln in ax.get_lines() if ln.get_color() == "C3"]
        assert len(drawn) == len(wrong)
        assert drawn[0].get_label() == f"loop closures judged wrong ({len(wrong)})"
        first = np.column_stack(drawn[0].get_data())
        pos = graph.positions()
        np.testing.assert_array_equal(first, pos[[wrong[0].from_id, wrong[0].to_id]])
        assert ax.get_title().startswith("chi2 of the inliers = ")
        assert (tmp_path / "g.png").stat().st_size > 0
    finally:
        matplotlib.pyplot.close(fig)
