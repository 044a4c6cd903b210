"""The benchmark report: every case run, its seed claims checked, one HTML page.

    python -m rkfx.report [--quick] [--out DIR] [--cases a,b] [--timeout S]

Each case of ``rkfx.cases`` runs in its own process (``python -m rkfx.cases.<name> --out
DIR/<name>``, with ``--quick`` its coarse settings), its output kept in ``DIR/<name>/log.txt``.
The case module's ``CLAIMS`` (``rkfx.report.claims.Claim``: the seed's statement with its
figure or equation, the run, the ``errors`` key, the comparison and bound) are evaluated on
its ``results.json``, and ``DIR/index.html`` shows per case the claims (PASS / FAILED), the
figures, the RKPM and FEM runs with their errors and wall times and, where there is one, a
time-to-accuracy table; at the top the machine, the date, the rkfx version and the total
wall time. A case that crashes is shown as FAILED with the tail of its log, and the report
still completes. Exit code 0 when every claim holds, 1 otherwise (2: bad arguments).

Modules: ``claims`` (Claim and its evaluation), ``run`` (the case processes), ``html`` (the page),
``__main__`` (the command line).
"""
