"""What the file system refuses is named: a full disk at any write, output names too long.

The full disk is a real one where the tests may mount a 1 MB tmpfs (root, as in CI; skipped
with the reason otherwise), and for the pipeline's own writes the NetCDF library's failure as
the issue found it (``RuntimeError: NetCDF: HDF error`` with the disk full). Names are checked
against the file system's ``NAME_MAX`` at its boundary, with the run's longest companion name.
"""

from __future__ import annotations

import errno
import os
import subprocess

import numpy as np
import pytest
import xarray as xr

from shipblock.cli import main
from shipblock.fragility import filesystem
from shipblock.fragility.pipeline import PipelineError, run_pipeline
from shipblock.fragility.store import ChunkStore, StoreError, write_dataset

from .test_pipeline import assert_same_results, write_pipeline


@pytest.fixture
def small_disk(tmp_path):
    """A folder on a 1 MB tmpfs, unmounted afterwards."""
    folder = tmp_path / "small"
    folder.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1M", "tmpfs", str(folder)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (needs root): {done.stderr.strip()}")
    try:
        yield folder
    finally:
        # lazily: HDF5 keeps a file it failed to close open (emptied, see store._failed)
        subprocess.run(["umount", "-l", str(folder)], check=False)


def _noise(nbytes: int) -> xr.Dataset:
    """Incompressible data of about ``nbytes`` bytes, with the metadata results carry."""
    values = np.random.default_rng(33).standard_normal(nbytes // 8)
    return xr.Dataset({"a": ("x", values, {"units": "1", "long_name": "noise"})},
                      coords={"x": ("x", np.arange(values.size), {"units": "1", "long_name": "i"})})


def test_a_full_disk_is_named_at_the_final_write(small_disk):
    path = small_disk / "result.nc"
    with pytest.raises(StoreError) as info:
        write_dataset(_noise(3_000_000), path)
    message = str(info.value)
    assert str(path) in message and "disk is full" in message
    assert list(small_disk.iterdir()) == []  # no temporary file left to fill the disk
    write_dataset(_noise(100_000), path)  # a dataset that fits is written as before
    assert xr.open_dataset(path).sizes["x"] == 12_500


def test_a_full_disk_is_named_at_a_partial_results_write(small_disk):
    store = ChunkStore(small_disk / "r.nc.partial", "f").open()
    big = np.random.default_rng(1).standard_normal(300_000)
    with pytest.raises(StoreError) as info:
        store.write(0, np.arange(big.size), {"a": big})
    assert "chunk-000000.npz" in str(info.value) and "disk is full" in str(info.value)
    assert sorted(p.name for p in store.directory.iterdir()) == ["manifest.json"]


def _hdf_error_on_a_full_disk(monkeypatch, fails):
    """``to_netcdf`` fails as netCDF4 does on a full disk for the files ``fails(path)`` picks,
    and the disk reads as full then."""
    real = xr.Dataset.to_netcdf
    failed = []

    def to_netcdf(self, path, *args, **kwargs):
        if fails(os.fspath(path)):
            failed.append(path)
            raise RuntimeError("NetCDF: HDF error")
        return real(self, path, *args, **kwargs)

    real_usage = filesystem.shutil.disk_usage

    def usage(folder):
        found = real_usage(folder)
        return found._replace(used=found.total - 4096, free=4096) if failed else found

    monkeypatch.setattr(xr.Dataset, "to_netcdf", to_netcdf)
    monkeypatch.setattr(filesystem.shutil, "disk_usage", usage)
    return failed


HISTORIES = '\n[histories]\nruns = [{record = "S0", im_level_g = 0.5}]\n'


@pytest.mark.parametrize("which", ["final", "history"])
def test_pipeline_names_the_file_and_a_full_disk_and_loses_nothing(tmp_path, monkeypatch, which):
    path = write_pipeline(tmp_path)
    path.write_text(path.read_text() + HISTORIES)
    reference = run_pipeline(path, output=tmp_path / "reference" / "result.nc", progress=False)
    out = tmp_path / "full" / "result.nc"
    target = "_histories" if which == "history" else "result.nc"
    failed = _hdf_error_on_a_full_disk(monkeypatch, lambda p: target in p)
    with pytest.raises(StoreError) as info:
        run_pipeline(path, output=out, progress=False)
    assert failed
    message = str(info.value)
    named = (out.parent / "result_histories" / "S0_im2.nc") if which == "history" else out
    assert message.startswith(f"cannot write {named}: the disk is full")
    assert "HDF" not in message
    assert not out.exists()
    monkeypatch.undo()

    from shipblock.fragility import batch

    calls = []
    real = batch.run_chunk
    monkeypatch.setattr(batch, "run_chunk", lambda *a, **k: (calls.append(1), real(*a, **k))[1])
    resumed = run_pipeline(path, output=out, progress=False)
    assert calls == []  # nothing lost: every run is taken from the partial results
    assert_same_results(reference, resumed)
    assert (out.parent / "result_histories" / "S0_im2.nc").is_file()


def test_a_write_error_that_is_not_a_full_disk_keeps_its_cause(tmp_path):
    exc = OSError(errno.EROFS, "Read-only file system")
    message = filesystem.write_failure(tmp_path / "x.nc", exc)
    assert message.startswith("Read-only file system") and "MB free" in message
    assert filesystem.write_failure(tmp_path / "x.nc", KeyError("x")) is None
    assert "quota exceeded" in filesystem.write_failure(tmp_path / "x.nc",
                                                        OSError(errno.EDQUOT, "Disk quota"))


def test_output_names_are_checked_against_name_max_with_the_temporary_file(tmp_path):
    limit = filesystem.name_max(tmp_path)
    longest = limit - len(".") - len(".XXXXXXXX.tmp")  # the temporary file's name is longest
    fits = tmp_path / ("r" * (longest - 3) + ".nc")
    assert filesystem.output_name_problem(fits) is None
    write_dataset(_noise(800), fits)  # and that name is really written, temporary file and all
    assert fits.is_file()
    too_long = tmp_path / "new" / ("r" * (longest - 2) + ".nc")  # one byte more; folder not yet made
    problem = filesystem.output_name_problem(too_long)
    assert f"{longest + 1} bytes long" in problem and f"at most {limit} bytes" in problem
    assert f"at most {longest} bytes" in problem  # what to do
    # bytes, not characters: two-byte letters halve the room
    assert filesystem.output_name_problem(tmp_path / ("é" * (longest // 2 + 1))) is not None


def test_a_name_too_long_at_write_time_is_named(tmp_path):
    """A history file's name comes from record ids and swept names: checked when written."""
    path = tmp_path / ("h" * 250 + ".nc")  # fits NAME_MAX, its temporary file's name does not
    with pytest.raises(StoreError) as info:
        write_dataset(_noise(800), path)
    assert str(info.value).startswith(f"cannot write {path}: a file name is too long")
    assert f"at most {filesystem.name_max(tmp_path)} bytes" in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_a_250_byte_output_name_is_refused_before_the_run(tmp_path, monkeypatch, capsys):
    from shipblock.fragility import batch

    monkeypatch.setattr(batch, "run_chunk", lambda *a, **k: pytest.fail("the batch ran"))
    path = write_pipeline(tmp_path)
    name = "x" * 247 + ".nc"
    with pytest.raises(PipelineError) as info:
        run_pipeline(path, output=tmp_path / "out" / name, progress=False)
    assert info.value.key == "output" and "250 bytes long" in str(info.value)
    assert not (tmp_path / "out").exists()  # refused before anything was made
    # the pipeline's own output key
    path.write_text(path.read_text().replace('output = "out/result.nc"', f'output = "{name}"'))
    with pytest.raises(PipelineError, match="250 bytes long"):
        run_pipeline(path, progress=False)
    # the command names its flag
    assert main(["run", str(path), "--output", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"shipblock: error: --output {tmp_path / name}: ") and "250 bytes" in err


def test_name_max_falls_back_where_the_file_system_does_not_say(monkeypatch, tmp_path):
    def no_answer(folder, name):
        raise OSError(errno.EINVAL, "no answer")

    monkeypatch.setattr(filesystem.os, "pathconf", no_answer)
    assert filesystem.name_max(tmp_path) == filesystem.DEFAULT_NAME_MAX
