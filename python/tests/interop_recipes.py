"""The interop recipes of docs/PYTHON.md, extracted and run as written: one copy of each recipe
(the documentation), checked by test_interop.py (trimesh, meshio, matplotlib) and by
bench/python/run.sh (pyvista, open3d)."""

import os
import pathlib
import re

import numpy as np

import focal

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "PYTHON.md"


def recipes() -> dict:
    """name -> code of every ```python block of docs/PYTHON.md whose first line is
    `# recipe: NAME ...`."""
    blocks = re.findall(r"```python\n(# recipe: (\S+).*?)```", DOC.read_text(), flags=re.S)
    return {name: code for code, name in blocks}


def run(name: str, workdir: pathlib.Path) -> dict:
    """Runs recipe `name` in `workdir` on mesh.ply (an irregular torus with its exact normals,
    written by focal) and checks that its curvature is focal's on the same arrays: the library's
    arrays reached focal in the file's vertex order. Returns the recipe's variables."""
    s = focal.generate_surface("torus", 3000, triangulation="irregular", seed=7)
    focal.write_mesh(workdir / "mesh.ply", s.V, s.F, s.N)
    code = recipes()[name]
    here = os.getcwd()
    os.chdir(workdir)
    try:
        namespace: dict = {"__name__": f"recipe_{name}"}
        exec(compile(code, f"docs/PYTHON.md recipe {name}", "exec"), namespace)
    finally:
        os.chdir(here)
    c = namespace["c"]
    # Recipes without the file's normals run the recommended estimator on the positions alone.
    expected = focal.curvature(s.V, s.F, s.N if "mesh.N" in code else None)
    H, ref = np.asarray(c.H), expected.H
    assert H.shape == ref.shape, (name, H.shape, ref.shape)
    assert np.array_equal(np.isnan(H), np.isnan(ref)), name
    ok = ~np.isnan(ref)
    if name == "pyvista":
        # VTK reads positions as float32: their rounding (6e-8 relative) changes H a little;
        # measured max |dH| / max |H| 4.4e-6 on this torus, bound 1e-4 (20x margin).
        assert np.abs(H[ok] - ref[ok]).max() <= 1e-4 * np.abs(ref[ok]).max(), name
    else:
        # float64 arrays in the file's order: the same bits as focal on the arrays themselves.
        assert np.array_equal(H[ok], ref[ok]), name
    return namespace
