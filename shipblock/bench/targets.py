"""The benchmarks' targets (issues 2, 4 and 21) and the verdicts the report gives on them."""

from __future__ import annotations


#: Targets of the project's issues 2 and 4: samples per second on one core in rocking-dominated
#: runs (with peak theta within ``peak_rotation_error`` [rad] of a converged run), runs per second
#: on all cores (2) of records of about 10k samples, wall time [s] and memory increase [bytes] of
#: a 100,000-run campaign, speed-up over pySLAMMER and scaling of the batch entry point; issue
#: 29's dock section: CPU seconds per run and wall seconds of a 10,000-run study on 2 cores.
TARGETS = {"rocking_samples_per_s": 2e7, "peak_rotation_error": 1e-4,
           "sliding_runs_per_s": 20_000, "rocking_runs_per_s": 1_000,
           "campaign_seconds": 120.0, "campaign_memory": 200e6, "pyslammer_speedup": 200.0,
           "batch_speedup": 1.8, "spectrum_seconds": 1.0,
           "section_seconds_per_run": 0.05, "section_study_seconds": 600.0}

#: Size of the response-spectrum case (the brief's requirement: ``spectrum_seconds`` for
#: ``SPECTRUM_PERIODS`` periods of a record of ``SPECTRUM_SAMPLES`` samples).
SPECTRUM_PERIODS = 2000
SPECTRUM_SAMPLES = 20_000

#: Record length [samples] the runs-per-second targets refer to.
TARGET_SAMPLES = 10_000

#: Default number of runs of the campaign (``--quick``: ``QUICK_CAMPAIGN_RUNS``).
CAMPAIGN_RUNS = 100_000

QUICK_CAMPAIGN_RUNS = 300


def timing_note(r):
    """How a :func:`~shipblock.bench.solver.throughput` figure was obtained, for the report."""
    spread, control = r["spread"], r["control_spread"]
    return (f"best of {r['rounds']} calls alternating with a control loop; median "
            f"{r['samples_per_s_median']:.3g}: the median call took {spread:.2f}x "
            f"the best, the control loop's {control:.2f}x")


def scaling_verdict(scaling, target=None):
    """Verdict on a :func:`~shipblock.bench.solver.batch_scaling` result against the target speed-up.

    A miss is said to be the machine's when the control loop timed in the same rounds missed
    the target too: no batch can scale better than the machine allows.
    """
    target = TARGETS["batch_speedup"] if target is None else target
    if scaling["speedup"] >= target:
        return verdict(True)
    if scaling["machine_speedup"] < target:
        return (f"{verdict(False)}, nor did the control loop: the machine allowed no more "
                "in this window")
    return verdict(False)


def verdict(ok):
    return "met" if ok else "NOT met"


def megabytes(n):
    return f"{n / 1e6:.0f} MB"
