"""Wall time of the discrepancy workflow on a 20-minute record at 80 Hz with every candidate (target: < 3 min).

The 'measurement' is the full surrogate on OLC 7 with the tower's fore-aft bending stiffness at 0.9 (a hidden
parametric truth); the candidate model is the nominal one; the candidates are all of
``fowt_env.discrepancy.CANDIDATES``: the eleven effects of ``surrogates.EFFECTS`` and the ten parameter multipliers
of ``surrogates.parameters.PARAMETERS``. Prints the wall time, the number of model simulations, the machine's load
(other jobs on the same cores slow every simulation), the process's CPU time (what the run costs when it has
the cores to itself) and the report.

Usage: python benchmarks/discrepancy.py
"""

import os
import time

import surrogates
from fowt_env import discrepancy
from surrogates.parameters import ParametricModel


def main() -> None:
    truth = ParametricModel(parameters={"tower_fa_stiffness": 0.9})
    measured = surrogates.simulate(truth, 7, duration=1200.0, dt=0.0125, seed=1)
    load = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), time.process_time()
    rep = discrepancy.run(measured, surrogates.FOWTModel(), surrogates.load_case(7))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"discrepancy workflow, 20-minute record at 80 Hz, {len(discrepancy.CANDIDATES)} candidates "
          f"({len(surrogates.EFFECTS)} effects + {len(discrepancy.CANDIDATES) - len(surrogates.EFFECTS)} "
          f"parameters): {wall:.1f} s wall, {rep.n_simulations} model simulations of 1200 s "
          f"({wall / max(rep.n_simulations, 1):.2f} s each); target < 180 s; load average at the start "
          f"{load:.1f} on {os.cpu_count()} cores; CPU time of this process {cpu:.1f} s (what the run costs "
          "without other jobs on the cores); hidden truth tower_fa_stiffness = 0.90")
    print(rep.summary())


if __name__ == "__main__":
    main()
