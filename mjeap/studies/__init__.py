"""Studies: many runs of actuators asked one question each. :mod:`mjeap.studies.sweep`
(parameter sweeps streamed to a resumable CSV, on local processes or Dask),
:mod:`mjeap.studies.optimize` (design optimisation under constraints; the function is
:func:`mjeap.optimize`), :mod:`mjeap.studies.stability_map` (Dadras et al. 2021's payload x
amplitude map) and :mod:`mjeap.studies.parameters` (a study's parameters as text: units and
values). The actuator variants a study builds are the model floor's
(:mod:`mjeap.model.variants`)."""
