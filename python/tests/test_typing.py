"""The package is typed: py.typed, annotated Python code and the extension's stub generated at
build time by nanobind's stubgen (python/CMakeLists.txt). mypy checks a use of the API, the
package's own code included, and must find the two deliberate type errors in it (so the check
cannot pass by seeing no types at all)."""

import os
import pathlib
import subprocess
import sys
import textwrap

import focal

PACKAGE = pathlib.Path(focal.__file__).parent


def test_stub_and_marker_are_shipped_beside_the_module():
    stub = PACKAGE / "_focal_ext.pyi"
    assert (PACKAGE / "py.typed").exists()
    assert stub.exists(), "the build generates _focal_ext.pyi beside the module"
    text = stub.read_text()
    public = [n for n in dir(focal._focal_ext) if not n.startswith("__")]
    missing = [n for n in public if f"def {n}(" not in text and f"class {n}:" not in text]
    assert not missing, f"stub is out of date, lacks {missing}"


def test_mypy_checks_a_use_of_the_api(tmp_path):
    program = tmp_path / "use_focal.py"
    program.write_text(textwrap.dedent("""
        import numpy as np
        import focal

        s = focal.generate_surface("sphere", 500)
        c: focal.Curvature = focal.curvature(s.V, s.F, s.N, estimator="paper")
        H: np.ndarray = c.H
        img: np.ndarray = focal.render(s.V, s.F, c.H)
        g: focal.GBuffer = focal.rasterise_gbuffer(s.V, s.F, s.N)
        k: focal.ImageCurvature = focal.image_space_curvature(g.position, g.normal, g.mask)
        wrong: str = focal.curvature(s.V, s.F)  # a deliberate error in the annotated package
        focal._focal_ext.read_mesh(1, 0)  # one that only the extension's stub can show
    """))
    env = dict(os.environ, MYPYPATH=str(PACKAGE.parent))
    r = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-error-summary", "--cache-dir", str(tmp_path / "c"),
         str(program)],
        env=env, capture_output=True, text=True, timeout=240)
    errors = [line for line in r.stdout.splitlines() if ": error:" in line]
    assert len(errors) == 2, r.stdout + r.stderr
    assert "use_focal.py:11:" in errors[0] and "Curvature" in errors[0], errors[0]
    assert "use_focal.py:12:" in errors[1] and '"bytes"' in errors[1], errors[1]
