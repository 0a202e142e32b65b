"""Reductions: the algorithms a trials team applies to its records.

Rules of this package (enforced by tests/test_separation.py): it reads RECORDS only — instrument
channels and the metadata a trials team has — through :mod:`vtrials.records.netcdf`; it never imports the
simulator, the force models, the vessel models, the environment or the truth, and never opens a truth
file. Every function takes arrays (SI units, stated in its docstring) and returns values with their
uncertainties (:class:`vtrials.reduce.estimate.Estimate`).
"""
