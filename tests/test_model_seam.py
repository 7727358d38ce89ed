"""The model seam: a second model plugs into the study machinery without editing it.

A toy model, a linear single-degree-of-freedom oscillator (period ``period``, damping ratio
``zeta``), is registered here and a small pipeline study (IDA on Sa, a swept damping ratio,
one limit state, time histories, a rerun) is run through it. The checks are closed forms:

* the oscillator's peak pseudo-acceleration :math:`\\omega^2 \\max|u|` at the design's own
  period and damping is by definition the Sa the record was scaled to, so it equals the IM
  level (to the round-off of two exact discretisations of the same piecewise-linear input:
  the toy's matrix-exponential first-order hold here, Nigam-Jennings in
  :mod:`shipblock.intensity`);
* the oscillator is linear, so at any damping its peak response over the IM level is the same
  at every level of a record;
* a limit state ``peak_pseudo_acceleration > 0.45 g`` is therefore exceeded exactly at the
  levels above 0.45 g, which fixes every record's IDA capacity interval.
"""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from scipy import signal

from shipblock.fragility.keys import key_table
from shipblock.fragility.pipeline import PipelineError, load_pipeline, rerun_case, run_pipeline
from shipblock.errors import ParameterError
from shipblock.models import (
    EDPInfo,
    Field,
    FieldError,
    Model,
    get_model,
    model_names,
    register_model,
    unregister_model,
)
from shipblock.units import STANDARD_GRAVITY as G

from .test_batch import make_catalogue

PERIOD = 1.5  # [s]: 150 samples a period at dt = 0.01 s, no oversampling of the Sa recursion
LEVELS_G = (0.2, 0.3, 0.4, 0.5, 0.6)
THRESHOLD_G = 0.45


@dataclass(frozen=True)
class Oscillator:
    period: float  # [s]
    zeta: float  # [-]


@dataclass
class OscillatorResult:
    """What :meth:`Model.simulate` returns: the summary and the histories."""

    summary: dict
    t: np.ndarray
    u: np.ndarray

    def to_dataset(self) -> xr.Dataset:
        return xr.Dataset({"u": ("time", self.u, {"units": "m", "long_name": "relative "
                                                  "displacement"})},
                          coords={"time": ("time", self.t, {"units": "s", "long_name": "time"})})


def oscillator_response(system: Oscillator, acc: np.ndarray, dt: float) -> np.ndarray:
    """Relative displacement of u'' + 2 zeta w u' + w^2 u = -a_g, exact for piecewise-linear
    a_g (first-order hold of the state-space system)."""
    w = 2 * np.pi / system.period
    a = np.array([[0.0, 1.0], [-w * w, -2.0 * system.zeta * w]])
    b = np.array([[0.0], [-1.0]])
    disc = signal.cont2discrete((a, b, np.array([[1.0, 0.0]]), np.zeros((1, 1))), dt,
                                method="foh")
    _, u, _ = signal.dlsim(disc, acc)
    return u[:, 0]


class OscillatorModel(Model):
    """A linear SDOF oscillator behind the seam (a test's second model)."""

    name = "toy_sdof"
    description = "linear single-degree-of-freedom oscillator"
    parameters = {
        "period": Field("period", (float,), "natural period", "s", required=True, low=0.01,
                        high=10.0),
        "zeta": Field("zeta", (float,), "damping ratio", "1", default=0.05, low=0.0,
                      high=1.0, high_open=True),
    }
    sweep_parameters = {"period": ("s", "natural period"), "zeta": ("1", "damping ratio")}
    edps = {
        "peak_pseudo_acceleration": EDPInfo("m/s^2", "peak pseudo-acceleration w^2 max|u|",
                                            "float", True),
        "failure": EDPInfo("1", "failure code (never fails)", "code", False),
    }
    outputs = {
        "peak_pseudo_acceleration": ("m/s^2", "peak pseudo-acceleration w^2 max|u|"),
        "peak_displacement": ("m", "peak relative displacement max|u|"),
        "failure": ("1", "failure code (never fails)"),
    }

    def __init__(self):
        self.batch_calls = []  # cases per call of the batch entry point

    def build(self, values):
        values = {"zeta": self.parameters["zeta"].default, **values}
        if values["zeta"] * values["period"] > 1.0:  # a relation no single range expresses
            raise FieldError("zeta", "zeta x period must not exceed 1 s")
        return Oscillator(float(values["period"]), float(values["zeta"]))

    def vary(self, system, values):
        return replace(system, **{k: float(v) for k, v in values.items()})

    def describe(self, system):
        return asdict(system)

    def _summary(self, system, h, dt):
        u = oscillator_response(system, h, dt)
        peak = float(np.max(np.abs(u)))
        return {"peak_pseudo_acceleration": (2 * np.pi / system.period) ** 2 * peak,
                "peak_displacement": peak, "failure": 0.0}, u

    def run_batch(self, systems, inputs, dts, cases, **options):
        self.batch_calls.append(len(cases))
        out = {name: np.empty(len(cases)) for name in self.outputs}
        for k, (i, s) in enumerate(np.asarray(cases).tolist()):
            summary, _ = self._summary(systems[s], inputs[i][0], dts[i])
            for name in out:
                out[name][k] = summary[name]
        return out

    def simulate(self, system, horizontal, vertical, dt, **options):
        summary, u = self._summary(system, np.asarray(horizontal), dt)
        return OscillatorResult(summary, dt * np.arange(u.size), u)


TOY_PIPELINE = f"""
schema_version = 1
output = "out/toy.nc"
processing = []

[records]
catalogue = "records/catalogue.toml"
ids = "all"

[system]
model = "toy_sdof"
period = {PERIOD}

[sweep]
zeta = [0.02, 0.05, 0.1]

[design]
type = "ida"
measure = "sa"
period = {PERIOD}
damping = 0.05
levels_g = {list(LEVELS_G)}
max_scale_factor = 100.0       # the synthetic records are weak at 1.5 s

[[limit_states]]
name = "strong"
edp = "peak_pseudo_acceleration"
threshold = {THRESHOLD_G * G!r}

[fit]
bootstrap = 0

[execution]
chunk_size = 8

[histories]
runs = [{{record = "S1", im_level_g = 0.5, zeta = 0.05}}]
"""


@pytest.fixture
def toy():
    model = register_model(OscillatorModel())
    yield model
    unregister_model(model.name)


def write_toy(tmp_path, text=TOY_PIPELINE):
    if not (tmp_path / "records" / "catalogue.toml").exists():
        make_catalogue(tmp_path / "records", n_records=3)
    path = tmp_path / "toy.toml"
    path.write_text(text)
    return path


def test_a_registered_model_runs_a_pipeline_study(tmp_path, toy):
    path = write_toy(tmp_path)
    assert load_pipeline(path).model is toy
    ds = run_pipeline(path, progress=False)
    # the study's grid, on the toy's outputs
    assert ds["peak_pseudo_acceleration"].dims == ("record", "im_level", "zeta")
    assert ds["peak_pseudo_acceleration"].attrs["units"] == "m/s^2"
    assert "peak_ship_slip" not in ds
    # whole chunks through the batch entry point: 3 records x 5 levels x 3 dampings in 8s
    assert toy.batch_calls == [8] * 5 + [5]
    levels = np.array(LEVELS_G) * G
    psa = ds["peak_pseudo_acceleration"].transpose("record", "im_level", "zeta").values
    # at the design's own period and damping the oscillator's response is Sa: the level
    np.testing.assert_allclose(psa[:, :, 1], np.broadcast_to(levels, (3, 5)), rtol=1e-9)
    # linear: response / level is the same at every level, for every damping
    ratio = psa / levels[None, :, None]
    np.testing.assert_allclose(ratio, np.broadcast_to(ratio[:, :1, :], ratio.shape), rtol=1e-9)
    # the swept damping reaches the model (Model.vary): another damping, another response
    assert (np.abs(ratio[:, 0, [0, 2]] - 1.0) > 1e-4).all()
    # Sd = Sa / w^2
    w2 = (2 * np.pi / PERIOD) ** 2
    np.testing.assert_allclose(ds["peak_displacement"].values * w2,
                               ds["peak_pseudo_acceleration"].values, rtol=1e-12)
    # the limit state on the toy's EDP, its IDA capacities at zeta = 0.05: (0.4 g, 0.5 g]
    exceeded = ds["exceeded"].sel(limit_state="strong", zeta=0.05)
    np.testing.assert_array_equal(exceeded.transpose("record", "im_level").values,
                                  np.broadcast_to(levels > THRESHOLD_G * G, (3, 5)))
    capacity = ds["ida_capacity"].sel(limit_state="strong", zeta=0.05).values
    np.testing.assert_allclose(capacity, 0.5 * G, rtol=1e-12)
    np.testing.assert_allclose(ds["ida_capacity_lower"].sel(limit_state="strong", zeta=0.05),
                               0.4 * G, rtol=1e-12)
    assert ds.attrs["system"] == '{"period": 1.5, "zeta": 0.05}'
    # the histories and a rerun go through the toy's simulate, equal to the batch's run
    (history,) = [f for f in ds["history_file"].values.ravel() if f]
    with xr.open_dataset(tmp_path / "out" / history) as h:
        peak = float(np.abs(h["u"]).max())
    batch_value = float(ds["peak_displacement"].sel(record="syn/S1", zeta=0.05).isel(im_level=3))
    assert peak == batch_value
    res = rerun_case(path, "S1", im_level_g=0.5, zeta=0.05)
    assert res.summary["peak_pseudo_acceleration"] == float(
        ds["peak_pseudo_acceleration"].sel(record="syn/S1", zeta=0.05).isel(im_level=3))


@pytest.mark.parametrize(
    ("edit", "key", "needle"),
    [
        (("period = 1.5\n\n[sweep]", "period = -1.0\n\n[sweep]"), "system.period",
         "[0.01, 10]"),
        (("period = 1.5\n\n[sweep]", "period = 1.5\nmass = 3.0\n\n[sweep]"), "system.mass",
         "allowed keys: model, period, zeta"),
        (("period = 1.5\n\n[sweep]", "period = 1.5\nzeta = 0.9\n\n[sweep]"), "system.zeta",
         "zeta x period"),
        (('model = "toy_sdof"', 'model = "toy_sdf"'), "system.model", "'toy_sdof'"),
        (("zeta = [0.02", "mu_ground = [0.3]\nzeta = [0.02"), "sweep.mu_ground",
         "allowed keys: period, zeta"),
        (('edp = "peak_pseudo_acceleration"', 'edp = "peak_ship_slip"'), "limit_states",
         "known EDPs: peak_pseudo_acceleration, failure"),
        (("[fit]", "[solver]\nrtol = 1e-6\n[fit]"), "solver.rtol", "unknown key"),
    ],
)
def test_the_model_declares_its_keys_and_errors_name_them(tmp_path, toy, edit, key, needle):
    path = write_toy(tmp_path, TOY_PIPELINE.replace(*edit))
    with pytest.raises(PipelineError) as info:
        load_pipeline(path)
    assert info.value.key == key and info.value.field == key, str(info.value)
    assert needle in str(info.value), str(info.value)


def test_the_key_table_lists_the_models_keys(toy):
    table = key_table(toy)
    assert "``system.period``" in table and "``sweep.zeta``" in table
    assert "``system.ship_mass``" not in table and "``solver.rtol``" not in table
    rigid = key_table()
    assert "``system.ship_mass``" in rigid and "``solver.rtol``" in rigid
    assert "``system.period``" not in rigid


# -- models registered by their path, imported when first asked for ---------------------------

LAZY_MODULE = """
from tests.test_model_seam import OscillatorModel


class LazyOscillator(OscillatorModel):
    name = "lazy_toy"
"""


@pytest.fixture
def lazy_module(tmp_path, monkeypatch):
    """A module ``lazy_toy_model`` on the path, not imported, with a model ``lazy_toy``."""
    (tmp_path / "lazy_toy_model.py").write_text(LAZY_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "lazy_toy_model"
    unregister_model("lazy_toy")
    unregister_model("misnamed")
    sys.modules.pop("lazy_toy_model", None)


def test_a_model_registered_by_its_path_is_imported_when_first_asked_for(lazy_module):
    register_model("lazy_toy_model:LazyOscillator", name="lazy_toy")
    assert "lazy_toy" in model_names()
    assert lazy_module not in sys.modules
    model = get_model("lazy_toy")
    assert lazy_module in sys.modules
    assert isinstance(model, OscillatorModel) and model.name == "lazy_toy"
    assert get_model("lazy_toy") is model  # made once
    # the loaded model is the registered one: re-registering its instance is no clash
    assert register_model(model) is model


def test_a_path_registration_is_checked(lazy_module):
    with pytest.raises(ParameterError, match="'package.module:Class'"):
        register_model("lazy_toy_model.LazyOscillator", name="lazy_toy")
    with pytest.raises(ParameterError, match="needs a name="):
        register_model("lazy_toy_model:LazyOscillator")
    with pytest.raises(ParameterError, match="already registered"):
        register_model("lazy_toy_model:LazyOscillator", name="section")
    with pytest.raises(ParameterError, match="name= is for a model registered by its path"):
        register_model(OscillatorModel(), name="toy")
    register_model("lazy_toy_model:LazyOscillator", name="misnamed")
    with pytest.raises(ParameterError, match="'misnamed'.*names itself 'lazy_toy'"):
        get_model("misnamed")


# a fresh process (this one has imported the section package already): a rigid study's pipeline
# is loaded with the command line imported; then the section model is asked for
_RIGID_STUDY_CHILD = """
import json, sys
import shipblock.cli
from shipblock.fragility.pipeline import load_pipeline
from shipblock.models import get_model, model_names

study = load_pipeline(sys.argv[1])
loaded = sorted(m for m in sys.modules if m.startswith(("shipblock.section", "shipblock.models.section")))
section = get_model("section")
print(json.dumps({"model": study.model.name, "names": list(model_names()), "loaded": loaded,
                  "kernel_after": "shipblock.section._kernel" in sys.modules,
                  "section_class": type(section).__module__ + "." + type(section).__name__}))
"""


def test_a_rigid_study_does_not_import_the_section_model():
    root = Path(__file__).resolve().parents[1]
    proc = subprocess.run([sys.executable, "-c", _RIGID_STUDY_CHILD,
                           str(root / "pipelines" / "demo.toml")],
                          capture_output=True, text=True, cwd=root, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.splitlines()[-1])
    assert out["model"] == "rigid"
    assert "section" in out["names"]
    assert out["loaded"] == []
    assert out["kernel_after"]
    assert out["section_class"] == "shipblock.models.section.SectionModel"
