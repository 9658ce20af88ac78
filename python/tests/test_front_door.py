"""focal.curvature as the one front door: meshes and clouds (F=None), the baselines by name,
tiles, warnings, and options that do not apply (include/focal/curvature.h)."""

import warnings

import numpy as np
import pytest

import focal
from test_clouds import sphere_points


def same(a, b):
    """Bitwise equality of two float arrays, NaN included."""
    return a.shape == b.shape and bool(np.all((a == b) | (np.isnan(a) & np.isnan(b))))


def test_a_cloud_is_the_cloud_estimate_with_the_command_lines_default():
    P, _ = sphere_points(n=3000, seed=4)
    c = focal.curvature(P)  # F None: a point cloud, normals estimated
    # k=0 is the library's adaptive default in both calls: the same fit, bit for bit.
    d = focal.cloud_curvature(P, k=0)
    for field in ("k1", "k2", "H", "K", "residual"):
        assert same(getattr(c, field), getattr(d, field)), field
    assert c.cloud is not None and c.cloud["normals_estimated"]
    assert c.cloud["k"] >= 16
    # Random samples of a sphere of radius 2, jets over >= 16 neighbours: H = 0.5 within 1%.
    assert np.nanmax(np.abs(c.H - 0.5)) < 0.005
    assert c.N.shape == P.shape


def test_a_mesh_is_the_estimate_and_tiles_keep_its_bits():
    s = focal.generate_surface("torus", 2500, triangulation="irregular", seed=2)
    whole = focal.curvature(s.V, s.F, s.N)
    tiled = focal.curvature(s.V, s.F, s.N, tile_vertices=600)
    for field in ("k1", "k2", "H", "K", "residual"):
        assert same(getattr(whole, field), getattr(tiled, field)), field
    assert whole.cloud is None and whole.crowded_count == 0


def test_the_baselines_by_name():
    s = focal.generate_surface("sphere", 2000, triangulation="irregular", seed=1)
    for name in ("meyer_2003", "cohen_steiner_morvan_2003", "lachaud_2020", "yang_2006",
                 "grinspun_2006"):
        c = focal.curvature(s.V, s.F, s.N, estimator=name)
        # Unit sphere, ~2000 vertices: every baseline converges to H = 1; 10% is far above
        # their discretisation error at this size and far below any sign or scale mistake.
        assert np.nanmedian(np.abs(c.H - 1.0)) < 0.1, name
    with pytest.raises(focal.InvalidInputError):
        focal.curvature(s.V, None, estimator="meyer_2003")  # a cloud has no faces


def test_options_of_the_other_input_kind_are_errors():
    s = focal.generate_surface("sphere", 500)
    with pytest.raises(focal.InvalidInputError, match="rings"):
        focal.curvature(s.V, rings=2)
    with pytest.raises(focal.InvalidInputError, match="k"):
        focal.curvature(s.V, s.F, k=24)
    with pytest.raises(focal.InvalidInputError, match="device"):
        focal.curvature(s.V, s.F, device="tpu")


def test_warnings_are_python_warnings_with_the_command_lines_text():
    s = focal.generate_surface("sphere", 800)
    N = s.N.copy()
    N[3] = 0.0  # a zero file normal: filled from the faces
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        focal.curvature(s.V, s.F, N, estimator="paper")
    messages = [str(w.message) for w in caught]
    assert messages == [
        "1 vertices have no usable normal in the file; estimated them from the faces"
    ]
