"""
Read, process and inspect a South Napa record
=============================================

The repository ships six three-component records of the 2014 South Napa earthquake
(``records/catalogue.toml``) as raw digitizer counts with their StationXML. Reading one through
the catalogue converts the counts to m/s^2 with the inventory;
:func:`shipblock.processing.process_motion` then applies the default processing chain and
records every step.
"""

import matplotlib.pyplot as plt

from shipblock import load_catalogue
from shipblock.intensity import intensity_measures
from shipblock.plot import plot_record, plot_spectrum
from shipblock.processing import default_chain, process_motion
from shipblock.units import STANDARD_GRAVITY as G0

catalogue = load_catalogue()
print("\n".join(catalogue))
entry = catalogue["south-napa-2014/NP.1765"]
motion = entry.read()
print(f"{entry.id}: {motion.npts} samples at dt = {motion.dt} s, components "
      f"{sorted(motion.components)}")

# %%
# The default chain, step by step (a pipeline file lists the same entries as
# ``[[processing]]`` tables).
for step in default_chain():
    print(step)
processed = process_motion(motion)
print(processed.metadata["processing"][-1][:200], "...")

# %%
# Intensity measures of the processed horizontal (SI units) and the acceleration, velocity and
# displacement histories.
ims = intensity_measures(processed.horizontal, processed.dt)
print(f"PGA = {ims['pga'] / G0:.3f} g, PGV = {ims['pgv']:.3f} m/s, "
      f"Arias = {ims['arias']:.3f} m/s, D5-95 = {ims['d5_95']:.1f} s")
plot_record(processed)

# %%
# The 5 %-damped pseudo-acceleration spectra of the horizontal before and after processing.
fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
plot_spectrum(motion.horizontal, motion.dt, ax=ax, label="raw (counts converted to m/s^2)")
plot_spectrum(processed.horizontal, processed.dt, ax=ax, label="processed")
ax.legend()
plt.show()
