"""Work spread over processes and Dask workers: the same results wherever it runs.

The bootstrap's resamples in any blocks, here, on local processes or on a Dask cluster of
several processes; a pipeline on such a cluster bit for bit equal to the local run; numba
threads per Dask task that never oversubscribe the cores.
"""

from __future__ import annotations

import contextlib

import numpy as np
import pytest

from shipblock.fragility import workers as W
from shipblock.fragility.fit import bootstrap, fit_ida, fit_msa
from shipblock.fragility.pipeline import run_pipeline
from shipblock.solver._threads import usable_cores

from .test_pipeline import assert_same_results, write_pipeline


@pytest.mark.parametrize(("cores", "threads", "expected"),
                         [(2, 2, 1), (2, 1, 2), (8, 2, 4), (8, 3, 2), (2, 4, 1), (1, 1, 1)])
def test_numba_threads_per_task_share_the_cores(cores, threads, expected):
    n = W.numba_threads_per_task(cores, threads)
    assert n == expected
    assert n * threads <= max(cores, threads)  # never more threads than cores (but one each)


def test_host_task_threads_sums_the_workers_of_each_host():
    class FakeClient:
        def scheduler_info(self):
            return {"workers": {
                "tcp://10.0.0.1:4001": {"host": "10.0.0.1", "nthreads": 2},
                "tcp://10.0.0.1:4002": {"host": "10.0.0.1", "nthreads": 2},
                "tcp://10.0.0.2:4001": {"host": "10.0.0.2", "nthreads": 8},
                "tcp://10.0.0.3:4001": {"nthreads": 1},  # no host field: taken from the address
            }}

    assert W.host_task_threads(FakeClient()) == {"10.0.0.1": 4, "10.0.0.2": 8, "10.0.0.3": 1}


@pytest.mark.parametrize(("n", "slots"), [(200, 1), (200, 2), (200, 7), (5, 4), (1, 3), (37, 2)])
def test_blocks_cover_the_replicates_in_order(n, slots):
    parts = W.blocks(n, slots)
    assert [i for b in parts for i in b] == list(range(n))
    assert len(parts) <= max(1, slots * W.BLOCKS_PER_SLOT)
    if n >= 2 * W.MIN_BLOCK:
        assert min(len(b) for b in parts) >= W.MIN_BLOCK


THETA, BETA = 0.6, 0.4


def _capacities(seed=8, n=25):
    rng = np.random.default_rng(seed)
    return THETA * np.exp(BETA * rng.standard_normal(n))


class _HereInBlocks(W.Workers):
    """Runs here, but in the blocks of ``slots`` parallel slots."""

    def __init__(self, slots):
        super().__init__(processes=1)
        self._slots = slots

    def slots(self):
        return self._slots


def test_bootstrap_does_not_depend_on_the_blocks():
    c = _capacities()
    serial = bootstrap(fit_ida, {"capacities": c}, n_boot=120, seed=11)
    for slots in (1, 2, 5, 30):
        split = bootstrap(fit_ida, {"capacities": c}, n_boot=120, seed=11,
                          workers=_HereInBlocks(slots))
        np.testing.assert_array_equal(split.medians, serial.medians)
        np.testing.assert_array_equal(split.betas, serial.betas)
        assert split.fit == serial.fit
    # and the band still covers the truth
    assert serial.fit.median_ci[0] < THETA < serial.fit.median_ci[1]


def test_bootstrap_on_local_processes_equals_serial():
    c = _capacities(seed=9)
    serial = bootstrap(fit_ida, {"capacities": c}, n_boot=64, seed=5)
    with W.Workers(processes=2, local_pool_seconds=0.0) as workers:
        pooled = bootstrap(fit_ida, {"capacities": c}, n_boot=64, seed=5, workers=workers)
        assert workers.used == ["processes"]
    np.testing.assert_array_equal(pooled.medians, serial.medians)
    np.testing.assert_array_equal(pooled.lower, serial.lower)


def test_short_bootstrap_stays_here():
    """Starting processes costs a second: a bootstrap estimated shorter runs here."""
    c = _capacities(seed=10)
    with W.Workers(processes=2) as workers:
        bootstrap(fit_ida, {"capacities": c}, n_boot=20, seed=5, workers=workers)
        assert workers.used == ["here"] and workers._pool is None


def test_many_short_bootstraps_pay_for_the_pool_together():
    """Work run here adds up: once it reaches the threshold, the pool takes the rest."""
    workers = W.Workers(processes=2, local_pool_seconds=1.0)
    items = [(1, 2), (3, 4)]
    assert workers.map(max, items, estimated_seconds=0.4) == [2, 4]
    assert workers.map(max, items, estimated_seconds=0.4) == [2, 4]
    assert workers.used == ["here", "here"] and workers.here_seconds == pytest.approx(0.8)
    assert workers.where(0.4) == "processes"  # 0.8 s done here + 0.4 s: the pool pays
    assert W.Workers(processes=1, local_pool_seconds=1.0).where(5.0) == "here"  # one core


def test_spawned_processes_only_where_the_main_script_is_guarded(tmp_path, monkeypatch):
    import sys
    import types

    def main(source=None, spec=None):
        module = types.ModuleType("__main__")
        if source is not None:
            path = tmp_path / f"script{len(list(tmp_path.iterdir()))}.py"
            path.write_text(source)
            module.__file__ = str(path)
        module.__spec__ = spec
        monkeypatch.setitem(sys.modules, "__main__", module)

    main()  # an interactive session, python -c
    assert W.main_is_safe_to_spawn()
    main("import shipblock\nshipblock.run_pipeline('study.toml')\n")  # would run again
    assert not W.main_is_safe_to_spawn()
    main("import shipblock\nif __name__ == '__main__':\n    shipblock.run_pipeline('s.toml')\n")
    assert W.main_is_safe_to_spawn()
    main("", spec=types.SimpleNamespace(name="shipblock.cli"))  # python -m shipblock.cli
    assert W.main_is_safe_to_spawn()


# -------------------------------------------------------------------------------------------
# a Dask cluster of two worker processes
# -------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def cluster_client():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        yield client


def _task_threads(hosts):
    from shipblock.fragility.workers import _task_numba_threads

    return _task_numba_threads(hosts)


def test_dask_tasks_get_their_share_of_the_cores(cluster_client):
    hosts = W.host_task_threads(cluster_client)
    assert sum(hosts.values()) == 2  # two workers of one thread
    got = cluster_client.gather([cluster_client.submit(_task_threads, hosts, pure=False)
                                 for _ in range(4)])
    assert got == [max(1, usable_cores() // 2)] * 4


def test_bootstrap_on_dask_equals_serial(cluster_client):
    rng = np.random.default_rng(4)
    exceeded = rng.random((30, 4)) < np.array([0.1, 0.4, 0.6, 0.9])
    levels = np.array([0.2, 0.4, 0.6, 0.8])
    serial = bootstrap(fit_msa, {"exceeded": exceeded}, im_levels=levels, n_boot=80, seed=2)
    with W.Workers(cluster_client, dask_seconds=0.0) as workers:
        remote = bootstrap(fit_msa, {"exceeded": exceeded}, im_levels=levels, n_boot=80, seed=2,
                           workers=workers)
        assert workers.used == ["dask"]
    np.testing.assert_array_equal(remote.medians, serial.medians)
    assert remote.fit == serial.fit


def test_pipeline_on_a_two_process_cluster_equals_the_local_run(cluster_client, tmp_path,
                                                                monkeypatch):
    """Runs and bootstrap (sent to the cluster whatever its length) bit for bit as locally."""
    path = write_pipeline(tmp_path, sweep='\n[sweep]\nmu_ground = [0.3, 0.6]\n')
    # three records at five levels: too few for the interval-censored fit's bootstrap (every
    # record's interval holds 0.4 g); the first-exceedance estimate has one, and what is tested
    # here is where the resamples run, not the estimator
    path.write_text(path.read_text().replace(
        "bootstrap = 20", 'bootstrap = 60\nida_method = "first_exceedance"'))
    local = run_pipeline(path, output=tmp_path / "local.nc", progress=False)
    used = []

    @contextlib.contextmanager
    def record_use(original_map):
        def spy(self, fn, items, estimated_seconds=float("inf")):
            out = original_map(self, fn, items, estimated_seconds)
            used.append(self.used[-1])
            return out
        monkeypatch.setattr(W.Workers, "map", spy)
        yield

    monkeypatch.setattr(W, "DASK_SECONDS", 0.0)
    with record_use(W.Workers.map):
        remote = run_pipeline(path, output=tmp_path / "dask.nc", client=cluster_client,
                              progress=False)
    assert used and set(used) == {"dask"}  # every bootstrap went to the cluster
    assert_same_results(local, remote)
    assert np.isfinite(remote["median_lower"].values).any()
