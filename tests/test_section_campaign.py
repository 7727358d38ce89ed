"""A seeded slice of the dock section's random campaign (the full one:
``python -m shipblock.bench.section_campaign``, results in ``docs/theory/section.md``): random
docks and motions of every kind run without an exception, with finite results, the energy
balance within ``ENERGY_TOL``, no negative loss, friction inside its cone, and the same failure,
kinds of event and demand parameters as a run at 1000 times tighter tolerances."""

from shipblock.bench.section_campaign import ENERGY_TOL, SUMMARY_TOL, run_case, summarise

SEED = 29
#: cases of seed 29 that run: two side lines (one fixed), one fixed side line (the ship tips
#: off it), two moving with wind, one fixed with wind, keel only. (Cases 7 and 11, two moving
#: side lines with 3000+ events, differ from their tight runs: docs/theory/section.md.)
#: Case 6 (one fixed side line) was refused as sliding at rest until its static state was
#: sought again from where it comes to rest under gravity alone (simulate.rest_state).
RAN = (3, 5, 6, 10, 12, 15)
#: docks refused, by their reason: a side line that would slide under the static load and, left
#: to settle, comes to rest with no static solution found from there (79); no static solution,
#: and left to settle the ship tips off its supports (27)
REFUSED = {79: "slides at rest", 27: "no static solution"}


def test_random_docks_and_motions_against_tight_runs():
    records = [run_case(SEED, case) for case in (*RAN, *REFUSED)]
    out = summarise(records)
    assert out["outcomes"] == {"ran": len(RAN), "refused": len(REFUSED)}
    assert out["refused"] == {"slides at rest": 1, "no static solution": 1}
    assert out["failures"] == {"none": len(RAN) - 1, "ship_tips": 1}
    assert out["violations"] == {}  # finite, energy, losses, cone, tight run
    assert out["residual_percentiles"][100] < ENERGY_TOL
    assert out["summary_diff_percentiles"][100] < SUMMARY_TOL
    kinds = {(r["sides"], r["wind"]) for r in records if r["outcome"] == "ran"}
    assert {(0, False), (1, False), (1, True), (2, False), (2, True)} <= kinds
    assert any(not m for r in records for m in r.get("moving", ()))  # a fixed side line
    assert all(r["compare"]["missed_kinds"] == [] for r in records if r["outcome"] == "ran")


#: cases of seed 29 that broke the energy checks before two kernel fixes (docs/theory/section.md,
#: *Verification*): a cap that let go and was met again at once went unseen until another event
#: (497, two side lines, and 1068, keel only: energy gains of 4.1 % and 3.9 % of the ground
#: work); the stick spring preloaded to mu_k N at every re-stick created energy in stick-slip
#: chatter (621 and 1502, one fixed side line: friction losses of -19 % and -13 %)
FIXED = (497, 621, 1068, 1502)


def test_the_cases_of_the_missed_reclosure_and_the_restick_keep_every_invariant():
    records = [run_case(SEED, case, compare=False) for case in FIXED]
    out = summarise(records)
    assert out["outcomes"] == {"ran": len(FIXED)}
    assert out["violations"] == {}
    assert out["residual_percentiles"][100] < ENERGY_TOL
    # friction, damping and crushing each dissipate: not one of them below zero
    assert all(r["negative_loss"] == 0.0 for r in records)


def test_peaks_of_the_total_cap_force_inside_steps_equal_the_tight_runs():
    # cases whose peak total cap force (a dashpot's spike after an impact) fell inside a step:
    # taken at step ends and events only it was 5.2e-2 (28) and 2.5e-2 (24) below the tight
    # run's; on the dense output (each step's middle, the parabola's vertex, just after events)
    # within 3e-7
    for case in (24, 28):
        rec = run_case(SEED, case)
        assert rec["outcome"] == "ran"
        assert rec["compare"]["peak_total_load_diff"] < 1e-4, case
