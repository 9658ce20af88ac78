"""Bad settings from Python: the thread rule, integers too large for the library, paths of every
kind, inputs the command line warns about or rejects, defaults shared with the command line, and
focal.distributed without Dask."""

import inspect
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import focal
import focal._clouds
import focal._meshes
import focal._progress


@pytest.fixture(scope="module")
def sphere():
    return focal.generate_surface("sphere", 500)


def test_threads_above_the_maximum_are_clamped_with_a_warning(sphere):
    one = focal.curvature(sphere.V, sphere.F, sphere.N, threads=1)
    for big in (10**6, 2**31, 2**70):
        with pytest.warns(UserWarning, match=r"threads asked for.*using 1024"):
            c = focal.curvature(sphere.V, sphere.F, sphere.N, threads=big)
        np.testing.assert_array_equal(c.H, one.H)


@pytest.mark.parametrize("bad", [-1, 1.5, "4"])
def test_threads_that_are_not_counts_are_invalid_input(sphere, bad):
    with pytest.raises(focal.InvalidInputError, match="threads"):
        focal.curvature(sphere.V, sphere.F, threads=bad)


def test_the_variable_follows_the_same_rule(sphere, monkeypatch):
    monkeypatch.setenv("FOCAL_NUM_THREADS", "abc")
    with pytest.raises(focal.InvalidInputError, match=r"FOCAL_NUM_THREADS='abc' is not a thread"):
        focal.curvature(sphere.V, sphere.F)
    monkeypatch.setenv("FOCAL_NUM_THREADS", "1000000")
    with pytest.warns(UserWarning, match="FOCAL_NUM_THREADS: 1000000 threads asked for"):
        focal.vertex_normals(sphere.V, sphere.F)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda s: focal.curvature(s.V, s.F, estimator="paper", rings=2**31), "rings"),
        (lambda s: focal.curvature(s.V, s.F, estimator="paper", rings=17), "rings"),
        (lambda s: focal.curvature(s.V, s.F, estimator="paper", lm_max_iterations=2**40),
         "lm_max_iterations"),
        (lambda s: focal.cloud_curvature(s.V, k=2**31), "k"),
        (lambda s: focal.cloud_curvature(s.V, k=1025), "k"),
        (lambda s: focal.curvature(s.V, k=2**31), "k"),
        (lambda s: focal.generate_surface("sphere", 10**12), "n"),
        (lambda s: focal.generate_surface("sphere", 2.5), "n"),
        (lambda s: focal.generate_surface("sphere", 100, seed=-1), "seed"),
        (lambda s: focal.render(s.V, s.F, s.k1, width=2**40), "width"),
        (lambda s: focal.curvature(s.V, s.F, tile_vertices=2**40), "tile_vertices"),
    ],
)
def test_integers_out_of_range_are_invalid_input_naming_the_argument(sphere, call, name):
    with pytest.raises(focal.InvalidInputError, match=rf"^{name} must"):
        call(sphere)


def test_paths_as_str_bytes_pathlike_and_not_utf8(sphere, tmp_path):
    import pathlib

    names = [
        str(tmp_path / "a.ply"),
        os.fsencode(tmp_path / "b.ply"),
        pathlib.Path(tmp_path / "c.ply"),
        os.fsencode(tmp_path) + b"/\xff\xfe-not-utf8.ply",
    ]
    for name in names:
        focal.write_mesh(name, sphere.V, sphere.F)
        m = focal.read_mesh(name)
        np.testing.assert_array_equal(m.V, sphere.V)
        np.testing.assert_array_equal(m.F, sphere.F)
    c = focal.curvature(sphere.V, sphere.F, sphere.N)
    odd = os.fsencode(tmp_path) + b"/\xff-fields.csv"
    focal.write_fields(odd, c)
    assert os.path.exists(odd)
    # An error naming a path that is not UTF-8 is still an error of the right type.
    with pytest.raises(focal.FocalIOError, match=r"\\xff"):
        focal.read_mesh(os.fsencode(tmp_path) + b"/\xff-missing.ply")


def test_nan_positions_warn_and_empty_inputs_raise(sphere):
    V = sphere.V.copy()
    V[3] = np.nan
    with pytest.warns(UserWarning, match=r"V: 1 of \d+ positions are not finite"):
        c = focal.curvature(V, sphere.F, sphere.N)
    assert c.undefined[3]
    empty = np.zeros((0, 3))
    with pytest.raises(focal.InvalidInputError, match="no vertices, nothing to compute"):
        focal.curvature(empty, np.zeros((0, 3), np.int32))
    with pytest.raises(focal.InvalidInputError, match="nothing to compute"):
        focal.curvature(empty)
    with pytest.raises(focal.InvalidInputError, match="nothing to compute"):
        focal.cloud_curvature(empty)


def test_all_zero_normals_are_read_as_absent_with_a_warning(sphere):
    zeros = np.zeros_like(sphere.V)
    without = focal.cloud_curvature(sphere.V)
    with pytest.warns(UserWarning, match="every normal is zero or not finite"):
        c = focal.cloud_curvature(sphere.V, zeros)
    np.testing.assert_array_equal(c.H, without.H)
    assert not c.undefined.all()
    mesh_without = focal.curvature(sphere.V, sphere.F)
    with pytest.warns(UserWarning, match="every normal is zero or not finite"):
        m = focal.curvature(sphere.V, sphere.F, np.full_like(sphere.V, np.nan))
    np.testing.assert_array_equal(m.H, mesh_without.H)


def test_cloud_defaults_are_the_command_lines():
    """One default per option: the cloud keywords of every Python entry point are those of
    focal.curvature (which are the C++ CloudOptions' and the command line's: k = 0, chosen from
    the cloud)."""
    front = focal._meshes._CLOUD_OPTIONS
    assert front["k"] == 0
    for function in (focal.cloud_curvature, focal.cloud_normals, focal.curvature):
        params = inspect.signature(function).parameters
        for name, default in front.items():
            if name in params:
                assert params[name].default == default, (function.__name__, name)


def test_cloud_curvature_and_curvature_of_a_cloud_agree():
    rng = np.random.default_rng(4)
    P = rng.normal(size=(3000, 3))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    P += 0.002 * rng.normal(size=P.shape)
    a = focal.cloud_curvature(P)
    b = focal.curvature(P)
    np.testing.assert_array_equal(a.H, b.H)


def test_distributed_without_dask_is_one_line_naming_the_extra(tmp_path):
    # A `distributed` package that cannot be imported stands for Dask being absent.
    blocker = tmp_path / "sitecustomize.py"
    blocker.write_text(
        "import sys\n"
        "class _Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in ('distributed', 'dask'):\n"
        "            raise ModuleNotFoundError(f'No module named {name!r}', name=name)\n"
        "sys.meta_path.insert(0, _Block())\n"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path)] + sys.path))
    code = (
        "import numpy as np, focal, focal.distributed as fd\n"
        "try:\n"
        "    fd.cloud_curvature(np.random.default_rng(1).normal(size=(100, 3)))\n"
        "except ModuleNotFoundError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == (
        "focal.distributed needs Dask (the distributed package): "
        "pip install 'focal-surfaces[distributed]'"
    )
    main = subprocess.run([sys.executable, "-m", "focal.distributed", str(tmp_path / "x.ply"),
                           "-o", str(tmp_path / "o.npz"), "--scheduler", "tcp://nowhere:1"],
                          env=env, capture_output=True, text=True)
    assert main.returncode == 2
    assert main.stderr.strip().count("\n") == 0, main.stderr
    assert "focal-surfaces[distributed]" in main.stderr


def test_the_extra_is_declared():
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "..", "..", "pyproject.toml")) as f:
        text = f.read()
    assert 'name = "focal-surfaces"' in text
    assert 'distributed = ["dask[distributed]"]' in text


def test_streamed_tiles_of_a_file_that_is_not_ply_say_so(sphere, tmp_path):
    import focal.stream

    off = tmp_path / "s.off"
    focal.write_mesh(off, sphere.V, sphere.F)
    with pytest.raises(focal.InvalidInputError, match=r"s.off: streamed tiles .* read binary PLY"):
        focal.stream._open(off)


@pytest.fixture(scope="module")
def large_sphere():
    # Over 1024 vertices: the library's loops run as parallel passes, whose progress is reported.
    return focal.generate_surface("sphere", 20000)


@pytest.mark.parametrize("threads", [1, 2])
def test_progress_callable_gets_stages_and_their_passes(large_sphere, threads):
    calls = []
    c = focal.curvature(large_sphere.V, large_sphere.F, estimator="paper", threads=threads,
                        progress=lambda stage, k, f: calls.append((stage, k, f)))
    plain = focal.curvature(large_sphere.V, large_sphere.F, estimator="paper", threads=threads)
    np.testing.assert_array_equal(c.H, plain.H)  # reporting changes nothing
    stages = [s for s, k, f in calls if k == 0 and f == 0.0]
    assert stages and "curvature" in stages, calls
    assert sorted(s for s, k, f in calls if k == 0 and f == 1.0) == sorted(stages)  # each ends
    passes = [(s, k, f) for s, k, f in calls if k > 0]
    assert passes, "no pass reported on %d thread(s)" % threads
    assert all(0.0 <= f <= 1.0 for _, _, f in passes)
    # Each pass starts at 0 and is reported done at 1; its fraction never goes back.
    for stage in {s for s, _, _ in passes}:
        for k in {k for s, k, _ in passes if s == stage}:
            fractions = [f for s, kk, f in passes if s == stage and kk == k]
            assert fractions[0] == 0.0 and fractions[-1] == 1.0, (stage, k, fractions)
            assert fractions == sorted(fractions)


def test_progress_callable_that_raises_stops_the_call(large_sphere):
    def fail(stage, k, f):
        if k > 0:
            raise KeyError("stop here")

    with pytest.raises(KeyError, match="stop here"):
        focal.curvature(large_sphere.V, large_sphere.F, estimator="paper", progress=fail)


def test_progress_must_be_a_callable(sphere):
    with pytest.raises(focal.InvalidInputError, match="progress must be"):
        focal.curvature(sphere.V, sphere.F, progress="yes")


class _FakeTqdm:
    made = []

    def __init__(self, total, desc, **kwargs):
        self.total, self.desc, self.kwargs, self.n, self.closed = total, desc, kwargs, 0, False
        self.descriptions = [desc]
        _FakeTqdm.made.append(self)

    def reset(self, total):
        self.n = 0

    def set_description(self, desc, refresh=True):
        self.descriptions.append(desc)

    def update(self, n):
        self.n += n

    def close(self):
        self.closed = True


def test_a_tqdm_bar_on_a_terminal_when_tqdm_is_installed(large_sphere, monkeypatch):
    import types

    module = types.ModuleType("tqdm")
    module.tqdm = _FakeTqdm
    monkeypatch.setitem(sys.modules, "tqdm", module)
    _FakeTqdm.made = []
    monkeypatch.setattr(focal._progress, "_stderr_is_terminal", lambda: False)
    focal.curvature(large_sphere.V, large_sphere.F, estimator="paper")
    assert _FakeTqdm.made == []  # not on a pipe
    focal.curvature(large_sphere.V, large_sphere.F, estimator="paper", progress=False)
    monkeypatch.setattr(focal._progress, "_stderr_is_terminal", lambda: True)
    focal.curvature(large_sphere.V, large_sphere.F, estimator="paper")
    assert _FakeTqdm.made, "no bar on a terminal"
    assert all(bar.closed for bar in _FakeTqdm.made)
    assert all(bar.kwargs["delay"] == 1.0 for bar in _FakeTqdm.made)  # a second before drawing
    bar = next(b for b in _FakeTqdm.made if b.desc == "curvature")
    assert any(d.startswith("curvature, pass ") for d in bar.descriptions)
    assert bar.n == 100  # its last pass done


def test_a_process_killed_by_sigterm_while_writing_leaves_no_temporary(tmp_path):
    import signal
    import time

    code = (
        "import focal\n"
        "s = focal.generate_surface('sphere', 2000000)\n"
        "print('ready', flush=True)\n"
        "while True:\n"
        "    focal.write_mesh('big.obj', s.V, s.F, s.N)\n"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    p = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "ready", p.stderr.read()
        deadline = time.monotonic() + 120
        seen = False
        while time.monotonic() < deadline and not seen:
            seen = any(n.startswith(".big.obj.tmp-") for n in os.listdir(tmp_path))
            if not seen:
                time.sleep(0.005)
        assert seen, "the temporary file was never seen"
        p.send_signal(signal.SIGTERM)
        p.wait(60)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == -signal.SIGTERM
    assert [n for n in os.listdir(tmp_path) if ".tmp-" in n] == []
