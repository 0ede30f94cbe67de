"""The Python module against the command line, explore's results and the reference values:
identical counts and outcomes everywhere, whatever the array layout, dtype or thread count."""
import csv
import json
import os

import h5py
import numpy as np
import pytest

from conftest import REFERENCE, SHARED_REFERENCE, run_cli

MODEL = dict(e=0.9, alpha=0.9)


def test_the_readme_example(superball):
    c = superball.count(0.05, -1, -2, e=0.9, alpha=0.9)
    assert (c.wall_bounces, c.outcome) == (8, superball.Outcome.left)
    assert str(c) == "Counts(wall_bounces=8, outcome=Outcome.left)"
    assert run_cli("count", "--xi", 0.05, "--U", -1, "--W", -2, "--e", 0.9, "--alpha", 0.9).stdout == \
        "8 wall bounces, outcome left\n"
    assert superball.OUTCOMES == ("invalid", "left", "missed", "capped")


def job_text(grid, model="e = 0.9\nalpha = 0.9", run="max_bounces = 1000"):
    return f"[model]\n{model}\n\n[grid]\n{grid}\n\n[run]\n{run}\n"


def explore_cli(tmp_path, name, text, ranks=2):
    job = tmp_path / f"{name}.toml"
    job.write_text(text)
    out = tmp_path / f"{name}.h5"
    run_cli("explore", job, "-o", out, "-q", ranks=ranks)
    return job, out


def read(path):
    with h5py.File(path, "r") as f:
        return f["wall_bounces"][()], f["outcome"][()], {k: f[k][()] for k in f if k not in ("wall_bounces", "outcome")}


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_count_equals_explore_on_a_canonical_grid(superball, tmp_path, threads):
    # 160 x 96 = 15360 launches of the quickstart region, near the wall where counts are high.
    _, out = explore_cli(tmp_path, "canonical", job_text(
        "xi = { min = 0.0, max = 0.2, n = 160 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 96 }"))
    counts, outcomes, coords = read(out)
    assert counts.size >= 10**4
    c = superball.count(coords["xi"][:, None], coords["U"], coords["W"][None, :], threads=threads, **MODEL)
    np.testing.assert_array_equal(c.wall_bounces, counts)
    np.testing.assert_array_equal(c.outcome, outcomes)
    assert counts.max() > 20 and len(np.unique(outcomes)) >= 2


def test_count_equals_explore_on_a_physical_grid(superball, tmp_path):
    _, out = explore_cli(tmp_path, "physical", job_text(
        'coordinates = "physical"\nx = { min = 0.0, max = 0.2, n = 128 }\nu = -2.0\nv = 2.0\n'
        "omega = { min = -400.0, max = 400.0, n = 100 }", model="e = 0.8\nalpha = 0.95\ng = 9.81\nradius = 0.03"))
    counts, outcomes, c = read(out)
    got = superball.count(x=c["x"][:, None], u=c["u"], v=c["v"], omega=c["omega"][None, :], g=9.81, radius=0.03,
                          e=0.8, alpha=0.95)
    np.testing.assert_array_equal(got.wall_bounces, counts)
    np.testing.assert_array_equal(got.outcome, outcomes)


def test_explore_in_process_writes_the_cli_s_file(superball, tmp_path):
    text = job_text("xi = { min = 0.0, max = 1.0, n = 120 }\nU = { min = -2.0, max = -0.5, n = 4 }\n"
                    "W = { min = -3.0, max = 3.0, n = 90 }", run="max_bounces = 500")
    job, cli = explore_cli(tmp_path, "volume", text, ranks=2)
    mine = tmp_path / "module.h5"
    ds = superball.explore(job, mine, threads=2)
    a, b = read(cli), read(mine)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    assert a[2].keys() == b[2].keys()
    for k in a[2]:
        np.testing.assert_array_equal(a[2][k], b[2][k])
    with h5py.File(cli, "r") as f, h5py.File(mine, "r") as g:
        assert set(f.attrs) == set(g.attrs)
        run = {"history", "date_created", "mpi_ranks", "threads", "wall_seconds", "build"}
        for k in set(f.attrs) - run:
            assert np.array_equal(f.attrs[k], g.attrs[k]), k
        for name in ("wall_bounces", "outcome", "xi", "U", "W"):
            assert set(f[name].attrs) == set(g[name].attrs), name
        assert g.attrs["threads"] == 2 and g.attrs["mpi_ranks"] == 1
        assert "superball.explore(" in g.attrs["history"] and "2 threads" in g.attrs["history"]
    # The dataset is the file as xarray reads it.
    import xarray as xr

    with xr.open_dataset(mine, engine="h5netcdf") as direct:
        assert ds.identical(direct)
    ds.close()
    assert run_cli("info", mine).stdout.count("superball.explore(") == 1


def test_explore_a_dict_into_memory(superball):
    job = {"model": {"e": 0.9, "alpha": 0.9}, "grid": {"xi": {"min": 0.0, "max": 1.0, "n": 64}, "U": -1.0,
                                                        "W": {"min": -3.0, "max": 3.0, "n": 48}},
           "run": {"max_bounces": 1000}}
    ds = superball.explore(job, threads=2)
    assert ds["wall_bounces"].dims == ("xi", "W") and ds["wall_bounces"].shape == (64, 48)
    c = superball.count(ds["xi"].values[:, None], -1.0, ds["W"].values[None, :], **MODEL)
    np.testing.assert_array_equal(ds["wall_bounces"].values, c.wall_bounces)
    np.testing.assert_array_equal(ds["outcome"].values, c.outcome)
    assert ds.attrs["date_created"] and ds.attrs["source"].startswith("superball ")
    assert ds["outcome"].attrs["flag_meanings"] == " ".join(superball.OUTCOMES)
    summary = superball.explore(job, dataset=False)
    assert summary["complete"] and summary["points_this_run"] == 64 * 48
    assert sum(summary["outcomes"].values()) == 64 * 48


def test_physical_and_canonical_forms_agree(superball):
    rng = np.random.default_rng(7)
    n = 20000
    x, u, v = rng.uniform(0.001, 0.3, n), rng.uniform(-4, -0.05, n), rng.uniform(0.1, 4, n)
    omega, g, radius = rng.uniform(-500, 500, n), 9.81, 0.025
    physical = superball.count(x=x, u=u, v=v, omega=omega, g=g, radius=radius, **MODEL)
    # The canonical coordinates as the library computes them (core/state.hpp to_canonical).
    xi, U, W = g * x / (2.0 * np.abs(u) * v), u / v, (omega * radius) / v
    canonical = superball.count(xi, U, W, **MODEL)
    np.testing.assert_array_equal(physical.wall_bounces, canonical.wall_bounces)
    np.testing.assert_array_equal(physical.outcome, canonical.outcome)
    # A sample against the command line, in both forms.
    for i in range(0, n, 4000):
        r = json.loads(run_cli("count", "--x", repr(x[i]), "--u", repr(u[i]), "--v", repr(v[i]), "--omega",
                               repr(omega[i]), "--e", 0.9, "--alpha", 0.9, "--json").stdout)
        assert (r["wall_bounces"], r["outcome"]) == (physical.wall_bounces[i], superball.OUTCOMES[physical.outcome[i]])
    # Not a launch toward the wall: invalid, 0 bounces (u >= 0, v <= 0, x <= 0).
    bad = superball.count(x=[0.1, 0.1, -0.1], u=[1.0, -1.0, -1.0], v=[1.0, -1.0, 1.0], omega=0.0, **MODEL)
    assert list(bad.outcome) == [0, 0, 0] and list(bad.wall_bounces) == [0, 0, 0]


def reference_rows():
    path = os.path.join(SHARED_REFERENCE, "canonical_counts.csv")
    if not os.path.exists(path):
        path = os.path.join(REFERENCE, "canonical_counts.csv")
    with open(path) as f:
        return list(csv.DictReader(f))


def test_shared_reference_counts(superball):
    rows = reference_rows()
    assert len(rows) > 20
    for r in rows:
        c = superball.count(float(r["xi"]), float(r["U"]), float(r["W"]), e_wall=float(r["e_wall"]),
                            alpha_wall=float(r["alpha_wall"]), e_floor=float(r["e_floor"]),
                            alpha_floor=float(r["alpha_floor"]))
        assert (c.wall_bounces, c.outcome.name) == (int(r["wall_bounces"]), r["outcome"]), r
    # All rows at once, one model at a time, as arrays.
    for model in {(r["e_wall"], r["alpha_wall"], r["e_floor"], r["alpha_floor"]) for r in rows}:
        sub = [r for r in rows if (r["e_wall"], r["alpha_wall"], r["e_floor"], r["alpha_floor"]) == model]
        e_wall, alpha_wall, e_floor, alpha_floor = map(float, model)
        c = superball.count(*(np.array([float(r[k]) for r in sub]) for k in ("xi", "U", "W")), e_wall=e_wall,
                            alpha_wall=alpha_wall, e_floor=e_floor, alpha_floor=alpha_floor)
        assert list(c.wall_bounces) == [int(r["wall_bounces"]) for r in sub]
        assert list(c.outcome_names()) == [r["outcome"] for r in sub]


def test_shared_reference_trajectory(superball):
    path = os.path.join(SHARED_REFERENCE, "trajectory_example.csv")
    if not os.path.exists(path):
        path = os.path.join(REFERENCE, "trajectory_example.csv")
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    first = rows[0]
    t = superball.trajectory(x=float(first["x_n"]), u=float(first["u_n"]), v=float(first["v_n"]),
                             omega=float(first["omega_n"]), e=0.9, alpha=0.9)
    floors = [i for i, ev in enumerate(t["event"]) if ev in ("launch", "floor")]
    assert len(floors) >= len(rows) - 1
    for r, i in zip(rows, floors):
        for column, key in (("x", "x_n"), ("u", "u_n"), ("v", "v_n"), ("omega", "omega_n")):
            assert t[column][i] == pytest.approx(float(r[key]), rel=1e-9, abs=1e-12), (r, column)
    assert t.wall_bounces == 12 and t.outcome == superball.Outcome.left


def test_layouts_and_dtypes_give_the_same_counts(superball):
    rng = np.random.default_rng(3)
    xi, U, W = rng.uniform(0, 1, (50, 40)), rng.uniform(-3, 0, (50, 40)), rng.uniform(-3, 3, (50, 40))
    want = superball.count(xi, U, W, **MODEL)
    # Transposed, sliced with steps, Fortran order, broadcast from smaller arrays.
    got = superball.count(xi.T.copy().T, np.asfortranarray(U), W[::1, ::1], **MODEL)
    np.testing.assert_array_equal(got.wall_bounces, want.wall_bounces)
    big = np.zeros((100, 80))
    big[::2, ::2] = xi
    got = superball.count(big[::2, ::2], U, W, **MODEL)
    np.testing.assert_array_equal(got.outcome, want.outcome)
    got = superball.count(xi.T, U.T, W.T, **MODEL)
    np.testing.assert_array_equal(got.wall_bounces, want.wall_bounces.T)
    # float32: the float32 values, exactly (read as they are, widened to double).
    f32 = [a.astype(np.float32) for a in (xi, U, W)]
    got = superball.count(*f32, **MODEL)
    ref = superball.count(*(a.astype(np.float64) for a in f32), **MODEL)
    np.testing.assert_array_equal(got.wall_bounces, ref.wall_bounces)
    np.testing.assert_array_equal(got.outcome, ref.outcome)
    # The other byte order is swapped, not misread; unaligned float64 (a view into a byte
    # buffer) is read right.
    got = superball.count(xi.astype(">f8"), U.astype(">f4").astype(">f8"), W.astype(">f8"), **MODEL)
    np.testing.assert_array_equal(got.wall_bounces, superball.count(xi, U.astype(np.float32), W, **MODEL).wall_bounces)
    raw = np.zeros(xi.size * 8 + 1, np.uint8)[1:].view(np.float64).reshape(xi.shape)
    raw[...] = xi
    assert not raw.flags.aligned
    np.testing.assert_array_equal(superball.count(raw, U, W, **MODEL).wall_bounces, want.wall_bounces)
    # Integers are converted; lists work; a grid by broadcasting.
    assert superball.count([1, 2], -1, 0, **MODEL).outcome.tolist() == [2, 2]  # xi >= 1: missed
    line = np.linspace(0.01, 0.99, 30)
    grid = superball.count(line[:, None], -1.0, line[None, :] * 6 - 3, **MODEL)
    assert grid.wall_bounces.shape == (30, 30)
    assert superball.count(np.float32(0.05), -1, -2, **MODEL).wall_bounces == 8


def test_threads_and_kernels_give_the_same_bits(superball):
    rng = np.random.default_rng(11)
    n = 300_001
    starts = rng.uniform(0, 1, n), rng.uniform(-3, 0, n), rng.uniform(-3, 3, n)
    want = superball.count(*starts, threads=1, kernel="scalar", **MODEL)
    for threads in (1, 2, 5):
        got = superball.count(*starts, threads=threads, **MODEL)
        np.testing.assert_array_equal(got.wall_bounces, want.wall_bounces)
        np.testing.assert_array_equal(got.outcome, want.outcome)
    empty = superball.count(np.zeros(0), -1, 0, **MODEL)
    assert empty.wall_bounces.shape == (0,) and empty.wall_bounces.dtype == np.uint32


def test_trajectory_has_the_cli_csv(superball):
    args = dict(x=0.02, u=-2, v=2, omega=-200, e=0.9, alpha=0.9)
    text = run_cli("trajectory", "--x", 0.02, "--u", -2, "--v", 2, "--omega", -200, "--e", 0.9, "--alpha", 0.9,
                   "--samples", 5).stdout
    rows = list(csv.DictReader(text.splitlines()))
    t = superball.trajectory(**args, samples=5)
    assert list(t) == list(rows[0])
    assert len(t["t"]) == len(rows)
    for column in t:
        if column in ("event", "contact"):
            assert list(t[column]) == [r[column] for r in rows]
        else:
            np.testing.assert_array_equal(t[column], [float(r[column]) for r in rows])  # the same doubles
    canonical = superball.trajectory(0.05, -1, -2, **MODEL)
    assert canonical.units.startswith("dimensionless") and canonical.wall_bounces == 8


def test_friction_and_inertia(superball):
    """SPEC section 1b through the module: mu = inf and inertia = 0.4 are the defaults, bit for
    bit; a row of tests/reference/mp_friction_counts.csv; each impact of a trajectory says
    whether it slid, with its tangential factor beta in [-1, alpha]."""
    xi, U, W = np.linspace(0.01, 0.99, 50), -1.0, np.linspace(-3, 3, 40)[:, None]
    plain = superball.count(xi, U, W, **MODEL)
    defaults = superball.count(xi, U, W, **MODEL, mu=float("inf"), inertia=0.4)
    np.testing.assert_array_equal(plain.wall_bounces, defaults.wall_bounces)
    np.testing.assert_array_equal(plain.outcome, defaults.outcome)
    assert (superball.count(xi, U, W, **MODEL, mu=1.0).wall_bounces != plain.wall_bounces).any()
    row = superball.count(0.00021810927870418665, -2.1256976997164694, -4.553173635519192, e=0.998, alpha=0.998, mu=1.5,
                          inertia=0.4)
    assert int(row.wall_bounces) == 839 and row.outcome == superball.Outcome.missed
    t = superball.trajectory(0.05, -1, -2, **MODEL, mu=0.3, inertia=2 / 3)
    impacts = [i for i, e in enumerate(t["event"]) if e in ("wall", "floor")]
    assert {t["contact"][i] for i in impacts} == {"grip", "slide"}
    for i in impacts:
        assert -1 <= t["beta"][i] <= 0.9 + 1e-12
        assert (t["beta"][i] == 0.9) == (t["contact"][i] == "grip")
    assert np.isnan(t["beta"][0]) and t["contact"][0] == ""


def test_fixed_points_and_continuation_print_what_the_cli_prints(superball):
    cli = json.loads(run_cli("fixed-points", "--e", 0.9, "--alpha", 0.99, "--corner", "--starts", 300,
                             "--format", "json").stdout)["cycles"]
    mine = superball.fixed_points(e=0.9, alpha=0.99, corner=True, starts=300)
    assert len(mine["xi"]) == len(cli) >= 2
    for i, c in enumerate(cli):
        assert (mine["xi"][i], mine["U"][i], mine["W"][i], mine["lambda"][i]) == (c["xi"], c["U"], c["W"], c["lambda"])
        assert mine["stability"][i] == c["stability"] and mine["corner"][i] == c["corner"]
        assert mine["eig1"][i] == complex(c["eigenvalues"][0]["re"], c["eigenvalues"][0]["im"])
    args = ["--e", 0.9, "--alpha", 0.99, "--param", "alpha", "--min", 0.97, "--max", 1, "--corner", "--max-step",
            0.01, "--starts", 300]
    text = run_cli("continue", *args).stdout
    rows = list(csv.DictReader(line for line in text.splitlines() if not line.startswith("#")))
    r = superball.continue_branch(e=0.9, alpha=0.99, param="alpha", min=0.97, max=1, corner=True, max_step=0.01,
                                  starts=300)
    points = r["points"]
    assert list(points) == list(rows[0])
    assert len(points["alpha"]) == len(rows) > 10
    for column in points:
        want = [row[column] for row in rows]
        if points[column].dtype.kind in "U":
            assert list(points[column]) == want, column
        elif points[column].dtype == bool:
            assert [str(int(v)) for v in points[column]] == want, column
        else:
            np.testing.assert_array_equal(points[column], np.asarray(want, dtype=float), err_msg=column)
    assert {"fold", "boundary", "end", "branch_point", "neimark_sacker"} & set(points["event"])


def test_open_validates_as_info_does(superball, tmp_path):
    _, out = explore_cli(tmp_path, "r", job_text("xi = { min = 0.0, max = 1.0, n = 40 }\nU = -1.0\nW = 0.5"), ranks=1)
    with superball.open(out) as ds:
        assert ds["wall_bounces"].dims == ("xi",)
        for key in ("history", "source", "date_created", "build", "job_toml"):
            assert ds.attrs[key], key
    # A value no outcome allows: refused with the reason, as superball info refuses it.
    damaged = tmp_path / "damaged.h5"
    damaged.write_bytes(out.read_bytes())
    with h5py.File(damaged, "r+") as f:
        f["outcome"][3] = 200
    info = run_cli("info", damaged, check=False)
    assert info.returncode == 2
    with pytest.raises(ValueError, match="outcome codes are 0 to 3"):
        superball.open(damaged)
    cut = tmp_path / "cut.h5"
    cut.write_bytes(out.read_bytes()[:4000])
    with pytest.raises(ValueError, match="cut.h5"):
        superball.open(cut)
    with pytest.raises(ValueError, match="missing.h5"):
        superball.open(tmp_path / "missing.h5")
    # A run not finished: its partial file is no result.
    job = tmp_path / "stopped.toml"
    job.write_text(job_text("xi = { min = 0.0, max = 1.0, n = 300 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 300 }",
                            run="max_bounces = 1000\ntile_points = 1024"))
    stopped = tmp_path / "stopped.h5"
    r = run_cli("explore", job, "-o", stopped, "-q", "--stop-after", 0, ranks=1, check=False)
    assert r.returncode == 1, r.stderr
    for path in (stopped, f"{stopped}.partial"):
        with pytest.raises(ValueError, match="not finished"):
            superball.open(path)
    ds = superball.explore(job, stopped, resume=True)
    assert int(ds["wall_bounces"].count()) == 300 * 300
    assert ds.attrs["history"].count("\n") == 1  # the CLI's run, then this one
    ds.close()
