"""Array-likes other than ndarrays (DLPack producers, __array_interface__ objects) and estimates
run from several Python threads at once."""

import threading

import numpy as np
import pytest

import focal


class DLPackOnly:
    """An array that offers only DLPack (as a PyTorch or JAX CPU tensor does, without NumPy)."""

    def __init__(self, a, device=(1, 0)):
        self._a, self._device = a, device

    def __dlpack__(self, **kwargs):
        return self._a.__dlpack__(**kwargs)

    def __dlpack_device__(self):
        return self._device


class InterfaceOnly:
    """An array that offers only __array_interface__ (as many buffer-owning libraries do)."""

    def __init__(self, a):
        self._a = a
        self.__array_interface__ = a.__array_interface__


@pytest.fixture(scope="module")
def torus():
    return focal.generate_surface("torus", 2000, triangulation="irregular", seed=3)


def test_dlpack_and_array_interface_inputs_are_viewed_not_copied(torus):
    for wrap in (DLPackOnly, InterfaceOnly):
        V = focal._as_rows(wrap(torus.V), "V", np.float64)
        assert np.shares_memory(V, torus.V), wrap.__name__
        F = focal._as_rows(wrap(torus.F), "F", np.int32)
        assert np.shares_memory(F, torus.F), wrap.__name__
        ref = focal.curvature(torus.V, torus.F, torus.N)
        c = focal.curvature(wrap(torus.V), wrap(torus.F), wrap(torus.N))
        np.testing.assert_array_equal(c.H, ref.H)


def test_device_arrays_are_a_clear_error(torus):
    on_gpu = DLPackOnly(torus.V, device=(2, 0))  # kDLCUDA
    with pytest.raises(focal.InvalidInputError, match="V is in device memory.*type 2"):
        focal.curvature(on_gpu, torus.F)


def test_two_python_threads_get_the_results_of_sequential_runs(torus):
    # Different estimates on different meshes at the same time (GIL released, the library's
    # own worker threads inside each): each equals its sequential run, bit for bit.
    sphere = focal.generate_surface("sphere", 3000, triangulation="irregular", seed=5)
    jobs = [
        lambda: focal.curvature(torus.V, torus.F, threads=2).to_dict(),
        lambda: focal.curvature(sphere.V, sphere.F, sphere.N, estimator="paper", rings=2).to_dict(),
    ]
    sequential = [job() for job in jobs]
    for _ in range(3):
        results = [None, None]
        barrier = threading.Barrier(2)

        def run(i):
            barrier.wait()
            results[i] = jobs[i]()

        threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for got, want in zip(results, sequential):
            for name in want:
                np.testing.assert_array_equal(got[name], want[name], err_msg=name)
