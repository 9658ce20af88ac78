"""The interop recipes of docs/PYTHON.md that run in every `make test` (trimesh, meshio and
matplotlib are in build/venv; pyvista and Open3D run in bench/python/run.sh)."""

import numpy as np

import interop_recipes


def test_the_documented_recipes_are_found():
    assert set(interop_recipes.recipes()) == {"trimesh", "meshio", "matplotlib", "pyvista",
                                              "open3d"}


def test_trimesh_recipe_colours_the_mesh_by_H(tmp_path):
    import trimesh

    ns = interop_recipes.run("trimesh", tmp_path)
    saved = trimesh.load(tmp_path / "mesh-H.ply", process=False)
    colours = np.asarray(saved.visual.vertex_colors)[:, :3].astype(int)
    H = np.nan_to_num(ns["c"].H)
    # coolwarm: red where H is well above 0 (the torus' outer half), blue well below.
    assert (colours[H > 0.5 * ns["lim"], 0] > colours[H > 0.5 * ns["lim"], 2]).all()
    assert (colours[H < -0.5 * ns["lim"], 2] > colours[H < -0.5 * ns["lim"], 0]).all()


def test_meshio_recipe_writes_the_fields(tmp_path):
    import meshio

    ns = interop_recipes.run("meshio", tmp_path)
    back = meshio.read(tmp_path / "mesh-curvature.vtu")
    np.testing.assert_array_equal(back.point_data["H"], ns["c"].H)
    np.testing.assert_array_equal(back.point_data["d1"], ns["c"].d1)


def test_matplotlib_recipe_draws_the_histogram(tmp_path):
    import matplotlib.image

    interop_recipes.run("matplotlib", tmp_path)
    picture = matplotlib.image.imread(tmp_path / "mesh-H-histogram.png")
    assert picture.shape[0] > 200 and picture.shape[1] > 400
