"""Studies at scale: tolerance, temperature and wear Monte Carlo over a template
(``gearcheck study``, :func:`gearcheck.study`). See :mod:`.core` for the flow, :mod:`.spec` for
the study file, :mod:`.run` for the levels and executors, :mod:`.stats` for the statistics."""
