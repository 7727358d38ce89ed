"""The dock-section kernel's two right-hand sides are one law: the per-spring :func:`rhs` (the
last stage, the event functions, the histories) and :func:`stage_rhs` (the inner stages, from
sums over each strip's springs kept per regime) are written independently, and must agree on
any state and any mix of regimes: free, elastic and crushing springs with permanent sets,
sticking, slipping and free strips, moving and fixed lines, wind and ground motion."""

from __future__ import annotations

import numpy as np

from shipblock.bench.section import navy_dock
from shipblock.section import BlockLine, DockSection, Wind
from shipblock.section import _kernel as K
from shipblock.section.model import assemble, static_state


def _docks():
    dock = navy_dock()
    fixed = tuple(BlockLine(block=line.block, n_blocks=line.n_blocks, offset=line.offset,
                            hull_height=line.hull_height, hull_slope=line.hull_slope,
                            moving=False) for line in dock.sides)
    yield dock
    yield DockSection(dock.ship, dock.keel, fixed, wind=Wind(force=2e4, height=6.0),
                      n_springs=7)


def test_the_inner_stages_from_regime_sums_equal_the_per_spring_right_hand_side():
    rng = np.random.default_rng(29)
    for dock in _docks():
        asm = assemble(dock, 0.02)
        init = static_state(asm)
        nb, ns, nsp = asm.n_bodies, asm.n_strips, asm.spring_f.shape[0]
        ag_y = rng.normal(scale=3.0, size=50)
        ag_z = rng.normal(scale=1.0, size=50)
        worst = 0.0
        for _ in range(200):
            x = init.x.copy()
            x[:3 * nb] += rng.normal(size=3 * nb) * np.tile([2e-3, 2e-4, 2e-3], nb)
            x[3 * nb:6 * nb] = rng.normal(scale=0.05, size=3 * nb)
            x[6 * nb:6 * nb + ns] = rng.normal(scale=1e-5, size=ns)
            reg = rng.integers(K.R_FREE, K.R_CRUSH + 1, nsp)
            dp = np.where(rng.random(nsp) < 0.5, rng.uniform(0.0, 2e-4, nsp), 0.0)
            fs = rng.choice([K.F_STICK, 1, -1, K.F_FREE], ns).astype(np.int64)
            t = rng.uniform(0.0, 0.2)
            full = np.zeros(asm.n_state)
            work = [np.zeros(nsp), np.zeros(nsp), np.zeros(ns), np.zeros((nsp, 2)),
                    np.zeros(nsp), np.zeros(nsp), np.zeros(ns), np.zeros(ns)]
            K.rhs(t, x, nb, ns, asm.mass, asm.inertia, asm.strip_f, asm.strip_i, asm.spring_f,
                  reg, dp, fs, asm.opt, ag_y, ag_z, 0.005, *work, full)
            normal = work[6]
            sums = np.zeros((ns, K.N_RS))
            K.regime_sums(asm.strip_i, asm.spring_f, reg, dp, sums)
            staged = np.zeros(asm.n_state)
            stage_n = np.full(ns, -np.inf)
            K.stage_rhs(t, x, nb, ns, asm.mass, asm.inertia, asm.strip_f, asm.strip_i,
                        asm.spring_f, fs, asm.opt, ag_y, ag_z, 0.005, sums, staged, stage_n)
            # every rate (positions, accelerations, stick springs or slip losses, energy rates),
            # each relative to its own size over the state vector's kind of entry
            for part in (slice(0, 3 * nb), slice(3 * nb, 6 * nb), slice(6 * nb, 6 * nb + ns),
                         slice(6 * nb + ns, None)):
                scale = max(np.abs(full[part]).max(), 1e-12)
                worst = max(worst, float(np.abs(staged[part] - full[part]).max() / scale))
            # the strips' normal forces the stages report, for the peaks inside a step
            np.testing.assert_allclose(stage_n, normal, rtol=1e-9,
                                       atol=1e-9 * np.abs(normal).max())
        assert 0.0 <= worst < 1e-8, worst
