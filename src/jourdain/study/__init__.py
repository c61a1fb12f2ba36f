"""Parameter studies: grids, lists and Monte-Carlo samples of one compiled model.

A study (:func:`load_study`, a TOML file described in ``docs/studies.md``) names a model file,
the varied parameters and initial states, and what to compute per case: ``evaluate`` (M, k, q,
ÿ, joint wrenches), ``linearize`` (eigenvalues, largest real part, stability verdict),
``simulate`` (final state, largest values, time series on fixed times) and ``critical`` (the
value of a parameter where the verdict changes, by bisection). :func:`run_study` derives and
compiles the model once, evaluates blocks of cases in one C call each where the work allows,
runs the blocks on this machine's cores or on a Dask cluster, saves them as they finish
(resumable) and returns an ``xarray.Dataset`` (written to NetCDF). Needs ``jourdain[study]``
(xarray, h5netcdf; dask.distributed for clusters).
"""

from .compute import VERDICTS, compute_block
from .dataset import open_study, results_dataset, to_dataset, write_netcdf
from .reader import load_study, loads_study
from .runner import Progress, run_study
from .spec import DESIGNS, DISTRIBUTIONS, StudyError, StudySpec

__all__ = ["DESIGNS", "DISTRIBUTIONS", "VERDICTS", "Progress", "StudyError", "StudySpec",
           "compute_block", "load_study", "loads_study", "open_study", "results_dataset",
           "run_study", "to_dataset", "write_netcdf"]
