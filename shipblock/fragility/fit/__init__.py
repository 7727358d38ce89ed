r"""Lognormal fragility functions fitted to multiple-stripe, incremental and cloud analyses.

A fragility function gives the probability that a limit state is exceeded given the
intensity measure (IM) of the ground motion,

.. math::
    :label: lognormal-fragility

    P(\mathrm{LS} \mid \mathrm{IM} = x) = \Phi\!\left(\frac{\ln(x/\theta)}{\beta}\right),

with median :math:`\theta` [IM units] and logarithmic standard deviation (dispersion)
:math:`\beta` [-]; :math:`\Phi` is the standard normal CDF.

Three kinds of analysis are supported, following Baker (2015) [1]_:

* **Multiple-stripe analysis (MSA)**: at each IM level :math:`x_j` a set of :math:`n_j` records
  is run and :math:`z_j` of them exceed the limit state. :func:`fit_mle` maximises the binomial
  likelihood; :func:`fit_msa` does the same from a record x IM-level exceedance matrix.
* **Incremental dynamic analysis (IDA)**: each record is scaled up until it exceeds the limit
  state, giving one IM capacity per record. On discrete IM levels a record's capacity is only
  known to lie between the last level that held and the first that failed:
  :func:`fit_ida_levels` fits the exceedance matrix by interval-censored maximum likelihood
  (:func:`fit_ida_intervals`, the default) or, as an option, takes the first exceeding level as
  the capacity (biased high by up to one level step). :func:`ida_capacities` turns an exceedance
  matrix into capacity bounds; :func:`fit_ida` fits capacities known exactly (e.g. from a
  hunt-and-fill IDA), by the method of moments or right-censored maximum likelihood.
* **Cloud analysis** of unscaled records: :func:`fit_cloud` regresses :math:`\ln \mathrm{EDP}`
  on :math:`\ln \mathrm{IM}` (Cornell et al. 2002 [2]_, Jalayer 2003 [3]_) or fits a probit
  to the binary outcome.

:func:`bootstrap` resamples records with replacement and refits, giving percentile confidence
bands for the curve and for :math:`\theta` and :math:`\beta`.

The package is split by concern: estimators (:mod:`~shipblock.fragility.fit.msa`,
:mod:`~shipblock.fragility.fit.ida`, :mod:`~shipblock.fragility.fit.cloud`, on the common
:mod:`~shipblock.fragility.fit._core`), the bootstrap (:mod:`~shipblock.fragility.fit.bootstrap`)
and the checkpoints of a study's fits (:mod:`~shipblock.fragility.fit.checkpoint`). Every name
is importable from ``shipblock.fragility.fit`` as before.

All functions are pure: no global random state is used or changed.

References
----------
.. [1] Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic
   structural analysis. *Earthquake Spectra*, 31(1), 579-599. doi:10.1193/021113EQS025M
.. [2] Cornell, C. A., Jalayer, F., Hamburger, R. O., & Foutch, D. A. (2002). Probabilistic
   basis for 2000 SAC Federal Emergency Management Agency steel moment frame guidelines.
   *Journal of Structural Engineering*, 128(4), 526-533.
.. [3] Jalayer, F. (2003). *Direct probabilistic seismic analysis: implementing non-linear
   dynamic assessments*. PhD thesis, Stanford University.
"""

from shipblock.fragility.fit._core import FragilityFit, FragilityFitError, lognormal_fragility
from shipblock.fragility.fit.bootstrap import BootstrapResult, bootstrap
from shipblock.fragility.fit.checkpoint import FIT_CHECKPOINT_INTERVAL, FitCheckpoint
from shipblock.fragility.fit.cloud import fit_cloud
from shipblock.fragility.fit.ida import (
    IDA_METHODS,
    IDACapacities,
    fit_ida,
    fit_ida_intervals,
    fit_ida_levels,
    ida_capacities,
)
from shipblock.fragility.fit.msa import fit_mle, fit_msa

__all__ = [
    "BootstrapResult",
    "FIT_CHECKPOINT_INTERVAL",
    "FitCheckpoint",
    "FragilityFit",
    "FragilityFitError",
    "IDACapacities",
    "IDA_METHODS",
    "bootstrap",
    "fit_cloud",
    "fit_ida",
    "fit_ida_intervals",
    "fit_ida_levels",
    "fit_mle",
    "fit_msa",
    "ida_capacities",
    "lognormal_fragility",
]
