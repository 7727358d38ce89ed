"""A seeded slice of the dock section's random campaign (the full one:
``python -m shipblock.bench.section_campaign``, results in ``docs/theory/section.md``): random
docks and motions of every kind run without an exception, with finite results, the energy
balance within ``ENERGY_TOL``, no negative loss, friction inside its cone, and the same failure,
kinds of event and demand parameters as a run at 1000 times tighter tolerances."""

from shipblock.bench.section_campaign import ENERGY_TOL, SUMMARY_TOL, run_case, summarise

SEED = 29
#: cases of seed 29 that run: one side line with wind, two, two with wind, keel only, one
RAN = (1, 7, 11, 15, 16)
#: a dock whose caps crush under the static load: refused, by that reason
REFUSED = 17


def test_random_docks_and_motions_against_tight_runs():
    records = [run_case(SEED, case) for case in (*RAN, REFUSED)]
    out = summarise(records)
    assert out["outcomes"] == {"ran": len(RAN), "refused": 1}
    assert out["refused"] == {"caps crush at rest": 1}
    assert out["violations"] == {}  # finite, energy, losses, cone, tight run
    assert out["residual_percentiles"][100] < ENERGY_TOL
    assert out["summary_diff_percentiles"][100] < SUMMARY_TOL
    kinds = {(r["sides"], r["wind"]) for r in records if r["outcome"] == "ran"}
    assert {(0, False), (1, True), (2, False), (2, True)} <= kinds
    assert any(not m for r in records for m in r.get("moving", ()))  # a fixed side line
    assert all(r["compare"]["missed_kinds"] == [] for r in records if r["outcome"] == "ran")
