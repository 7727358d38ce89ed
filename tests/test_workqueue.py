"""The batch work queue: every case run exactly once, results independent of the schedule."""

import numba
import numpy as np
from numba import njit, prange

from shipblock import RecordSet, ShipBlockSystem, simulate_batch
from shipblock.solver._workqueue import claim_next


@njit(parallel=True)
def _claim_all(n, n_workers, counter, times_claimed, claimed_by):
    for w in prange(n_workers):
        while True:
            c = claim_next(counter)
            if c >= n:
                break
            times_claimed[c] += 1
            claimed_by[c] = w
    return counter[0]


def test_each_value_is_claimed_once_under_contention():
    n = 200_000
    times_claimed = np.zeros(n, dtype=np.int64)
    claimed_by = np.full(n, -1, dtype=np.int64)
    workers = numba.get_num_threads()
    final = _claim_all(n, workers, np.zeros(1, dtype=np.int64), times_claimed, claimed_by)
    assert (times_claimed == 1).all()  # no value lost, none handed out twice
    assert final == n + workers  # each worker's last claim overshoots by one
    assert claimed_by.min() >= 0 and claimed_by.max() < workers


def _uneven_batch():
    """Cases of very different cost: long rocking runs among runs that stay at rest."""
    rng = np.random.default_rng(11)
    dt = 0.01
    t = np.arange(3000) * dt
    pulse = 4.0 * np.sin(2 * np.pi * 1.5 * t) * np.exp(-0.2 * t) + rng.normal(0, 0.3, t.size)
    system = ShipBlockSystem(ship_mass=2e5, block_mass=500.0, n_blocks=8, half_width=0.3,
                             half_height=0.6, mu_s_ground=0.8, mu_k_ground=0.7, mu_s_ship=0.8,
                             mu_k_ship=0.7)
    scales = np.r_[np.full(12, 0.01), np.linspace(0.5, 1.2, 12)]
    cases = np.column_stack([np.zeros_like(scales), np.zeros_like(scales), scales, scales])
    return system, [(pulse, 0.3 * pulse)], dt, cases


def test_batch_results_do_not_depend_on_threads_or_case_order():
    system, records, dt, cases = _uneven_batch()
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        serial = simulate_batch(system, records, dt, cases)
    finally:
        numba.set_num_threads(threads)
    parallel = simulate_batch(system, records, dt, cases)
    order = np.random.default_rng(3).permutation(len(cases))
    shuffled = simulate_batch(system, records, dt, cases[order])
    assert serial["n_impacts"][12:].sum() > 0  # the heavy cases do rock
    for key, values in serial.items():
        np.testing.assert_array_equal(parallel[key], values, err_msg=key)
        np.testing.assert_array_equal(shuffled[key], values[order], err_msg=key)


def test_packed_records_give_the_same_results():
    """A RecordSet packed once gives what the list of records gives, call after call."""
    system, records, dt, cases = _uneven_batch()
    records = records + [(records[0][0][::-1].copy(), None)]
    cases = np.vstack([cases, [1, 0, 0.8, 0.0]])
    listed = simulate_batch(system, records, dt, cases)
    packed = RecordSet(records, dt)
    assert len(packed) == 2 and packed.has_v.tolist() == [True, False]
    for _ in range(2):
        again = simulate_batch(system, packed, cases=cases)
        for key, values in listed.items():
            np.testing.assert_array_equal(again[key], values, err_msg=key)
