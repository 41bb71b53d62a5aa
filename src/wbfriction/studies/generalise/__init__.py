"""The randomised generalisation benchmark: scenarios drawn from seeds, each a MuJoCo-simulated log with a known
truth, run through the documented routes and scored on what the routes wrote (``benchmarks/bench_generalise.py``).

* :mod:`~wbfriction.studies.generalise.scenario`: the draw (:func:`draw`) and the split of the seeds (:func:`split`);
* :mod:`~wbfriction.studies.generalise.laws`: the friction laws simulated and the truth;
* :mod:`~wbfriction.studies.generalise.urdf`: random serial chains and perturbed models;
* :mod:`~wbfriction.studies.generalise.simulate`: a scenario's log, URDFs and TOML;
* :mod:`~wbfriction.studies.generalise.score`: the route run and scored.
"""
