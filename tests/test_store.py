"""Tests of the partial-chunk store and the atomic NetCDF writer."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from shipblock.fragility.store import (
    RUN_VARIABLES,
    ChunkStore,
    StoreError,
    check_metadata,
    open_results,
    write_dataset,
)
from shipblock.solver import MODE_TIME_FIELDS, SUMMARY_FIELDS


def test_every_summary_field_has_units_and_long_name():
    for name in [*SUMMARY_FIELDS, *MODE_TIME_FIELDS, "peak_rotation_ratio"]:
        units, long_name = RUN_VARIABLES[name]
        assert units and long_name
    assert RUN_VARIABLES["peak_ship_slip"][0] == "m"
    assert RUN_VARIABLES["time_in_mode_3"][0] == "s"


def test_time_in_mode_variables_say_what_the_mode_is():
    """Mode k's long name has the paper's wording and its three interface states
    (shipblock.modes: mode 3 rocks on stuck interfaces, mode 5 slides at both)."""
    assert RUN_VARIABLES["time_in_mode_3"][1] == (
        "time spent in mode 3: blocks rock (blocks on ground stick, blocks rocking, ship on "
        "blocks stick)")
    assert RUN_VARIABLES["time_in_mode_5"][1] == (
        "time spent in mode 5: blocks and ship slide (blocks on ground slide, blocks at rest, "
        "ship on blocks slide)")


@pytest.mark.parametrize(("umask", "mode"), [(0o022, 0o644), (0o027, 0o640), (0o077, 0o600)])
def test_result_files_get_the_permissions_of_a_new_file(tmp_path, umask, mode):
    """Not tempfile's 0600: 0666 less the umask, as any new file."""
    import os
    import stat

    ds = xr.Dataset({"a": ("x", np.arange(3.0), {"units": "m", "long_name": "a"})},
                    coords={"x": ("x", np.arange(3), {"units": "1", "long_name": "x"})})
    old = os.umask(umask)
    try:
        path = write_dataset(ds, tmp_path / "r.nc")
    finally:
        os.umask(old)
    assert stat.S_IMODE(path.stat().st_mode) == mode
    assert [p.name for p in tmp_path.iterdir()] == ["r.nc"]  # no temporary file left


def test_chunk_store_round_trip_and_fingerprint(tmp_path):
    store = ChunkStore(tmp_path / "p", "abc").open({"n_cases": 10})
    assert store.completed() == set()
    arrays = {"peak_ship_slip": np.array([0.1, np.nan, 0.3]),
              "run_error": np.array(["", "solver error", ""])}
    store.write(2, [6, 7, 8], arrays)
    # a temporary file left by a killed writer is ignored
    (tmp_path / "p" / ".chunk-000003.npz.xyz.tmp").write_bytes(b"half")
    assert store.completed() == {2}
    cases, back = ChunkStore(tmp_path / "p", "abc").open().read(2)
    np.testing.assert_array_equal(cases, [6, 7, 8])
    np.testing.assert_array_equal(back["peak_ship_slip"], arrays["peak_ship_slip"])
    assert list(back["run_error"]) == ["", "solver error", ""]
    with pytest.raises(StoreError, match="different run"):
        ChunkStore(tmp_path / "p", "other").open()
    store.remove()
    assert not (tmp_path / "p").exists()


def test_chunk_file_layout_and_older_layout_still_read(tmp_path):
    store = ChunkStore(tmp_path / "p", "abc").open()
    names = list(RUN_VARIABLES)
    arrays = {name: np.arange(4.0) + i for i, name in enumerate(names)}
    arrays["run_error"] = np.full(4, "", dtype="U80")
    store.write(0, [0, 1, 2, 3], arrays)
    with np.load(tmp_path / "p" / "chunk-000000.npz") as data:
        assert sorted(data.files) == ["cases", "names", "v_run_error", "values"]
        assert data["values"].shape == (len(names), 4)
        assert data["v_run_error"].dtype == np.dtype("U1")  # empty messages stored narrow
    cases, back = store.read(0)
    assert list(back) == [*names, "run_error"]
    for name in names:
        np.testing.assert_array_equal(back[name], arrays[name])
    # one entry per variable, as written by shipblock 0.1.0 before the 2-D layout
    np.savez(tmp_path / "p" / "chunk-000001.npz", cases=np.arange(4, 6),
             v_peak_ship_slip=np.array([0.5, np.nan]), v_run_error=np.array(["", "x"]))
    cases, back = store.read(1)
    np.testing.assert_array_equal(cases, [4, 5])
    np.testing.assert_array_equal(back["peak_ship_slip"], [0.5, np.nan])
    assert list(back["run_error"]) == ["", "x"]


def test_unreadable_chunk_raises_store_error(tmp_path):
    store = ChunkStore(tmp_path / "p", "abc").open()
    (tmp_path / "p" / "chunk-000000.npz").write_bytes(b"garbage")
    assert store.completed() == {0}
    with pytest.raises(StoreError, match="unreadable"):
        store.read(0)
    store.discard(0)
    assert store.completed() == set()


def _dataset():
    return xr.Dataset(
        {
            "peak_ship_slip": (("record", "im_level"), np.array([[0.0, np.nan], [0.1, 0.2]]),
                               {"units": "m", "long_name": "peak ship slip"}),
            "record_error": (("record",), np.array(["", "bad file"], dtype=object),
                             {"units": "1", "long_name": "record error"}),
            "exceeded": (("record", "im_level"), np.array([[False, True], [True, True]]),
                         {"units": "1", "long_name": "exceeded"}),
        },
        coords={
            "record": ("record", np.array(["a", "b"], dtype=object),
                       {"units": "1", "long_name": "record"}),
            "im_level": ("im_level", [1.0, 2.0], {"units": "m/s^2", "long_name": "level"}),
        },
        attrs={"pipeline": "x = 1\n"},
    )


def test_write_dataset_is_compressed_and_round_trips(tmp_path):
    ds = _dataset()
    path = write_dataset(ds, tmp_path / "sub" / "r.nc")
    assert [p.name for p in path.parent.iterdir()] == ["r.nc"]  # no temporary file left
    back = open_results(path)
    xr.testing.assert_identical(back, ds)
    assert back["peak_ship_slip"].encoding["zlib"] is True
    assert back["exceeded"].dtype == bool
    with xr.open_dataset(path) as plain:
        xr.testing.assert_identical(plain.load(), ds)


def test_write_dataset_refuses_missing_metadata_and_keeps_old_file(tmp_path):
    path = write_dataset(_dataset(), tmp_path / "r.nc")
    before = path.read_bytes()
    bad = _dataset()
    del bad["peak_ship_slip"].attrs["units"]
    with pytest.raises(StoreError, match="'peak_ship_slip' has no 'units'"):
        check_metadata(bad)
    with pytest.raises(StoreError):
        write_dataset(bad, path)
    assert path.read_bytes() == before


def test_fit_group_is_kept_apart_from_the_chunks(tmp_path):
    store = ChunkStore(tmp_path / "p", "abc").open()
    store.write(0, [0, 1], {"peak_ship_slip": np.array([0.1, 0.2])})
    fits = {"median": np.array([1.5, np.nan]), "n_fit_records": np.array([3, 0]),
            "fit_method": np.array(["mle", ""]), "capacity": np.array([[1.0, np.inf], [2.0, 3.0]])}
    store.write(0, [5, 7], fits, group="fit")
    assert store.completed() == {0} and store.completed("fit") == {0}
    assert sorted(p.name for p in (tmp_path / "p").glob("*.npz")) == ["chunk-000000.npz",
                                                                      "fit-000000.npz"]
    numbers, back = store.read(0, "fit")
    np.testing.assert_array_equal(numbers, [5, 7])
    for name, value in fits.items():
        np.testing.assert_array_equal(back[name], value)
        assert back[name].dtype.kind == value.dtype.kind
    store.discard(0, "fit")
    assert store.completed("fit") == set() and store.completed() == {0}
    with pytest.raises(StoreError, match="unknown file group"):
        store.completed("chunks")


def test_stale_temporary_files_of_the_same_output_are_removed(tmp_path):
    """Only names the writers themselves make (``.<name>.<8 random characters>.tmp``) for this
    output are removed; other outputs' and look-alike files stay."""
    from shipblock.fragility.store import remove_stale_temporaries

    out = tmp_path / "r.nc"
    ours = [tmp_path / ".r.nc.k2_9abcd.tmp", tmp_path / ".r.nc.zzzzzzzz.tmp"]
    others = [tmp_path / ".r.nc.short.tmp", tmp_path / ".rr.nc.abcdefgh.tmp",
              tmp_path / ".r.nc.abcdefgh.tmp.bak", tmp_path / "r.nc.abcdefgh.tmp",
              tmp_path / ".r.nc.abc-efgh.tmp", tmp_path / "r.nc"]
    for p in ours + others:
        p.write_text("x")
    assert sorted(remove_stale_temporaries(out)) == sorted(ours)
    assert all(p.exists() for p in others) and not any(p.exists() for p in ours)
    assert remove_stale_temporaries(tmp_path / "missing" / "r.nc") == []
    # the names are those write_dataset uses: a real temporary name matches
    from shipblock.fragility.store import _temporary

    fd, name = _temporary(out)
    os.close(fd)
    assert remove_stale_temporaries(out) == [Path(name)]


def test_chunk_store_open_removes_its_own_stale_temporary_files(tmp_path):
    store = ChunkStore(tmp_path / "p", "abc").open()
    d = tmp_path / "p"
    ours = [d / ".chunk-000003.npz.abcdefgh.tmp", d / ".fit-000001.npz.a1b2c3d4.tmp",
            d / ".manifest.json.abcdefgh.tmp"]
    others = [d / ".chunk-000003.npz.xyz.tmp", d / ".notes.txt.abcdefgh.tmp"]
    for p in ours + others:
        p.write_bytes(b"half")
    store.write(1, [4], {"peak_ship_slip": np.array([0.5])})
    ChunkStore(d, "abc").open()
    assert not any(p.exists() for p in ours)
    assert all(p.exists() for p in others)
    assert store.completed() == {1}
