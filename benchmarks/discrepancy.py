"""Wall time of the discrepancy workflow on a 20-minute record at 80 Hz (target: under 3 minutes).

The 'measurement' is the full surrogate on OLC 7; the candidate model lacks aerodynamic damping; every effect
of ``surrogates.EFFECTS`` (ten) is a candidate. Prints the wall time, the number of greedy rounds and the
report (what was named).

Usage: python benchmarks/discrepancy.py
"""

import time

import surrogates
from fowt_env import discrepancy


def main() -> None:
    full = surrogates.FOWTModel()
    measured = surrogates.simulate(full, 7, duration=1200.0, dt=0.0125, seed=1)
    t0 = time.perf_counter()
    rep = discrepancy.run(measured, full.without("aero_damping"), surrogates.load_case(7))
    wall = time.perf_counter() - t0
    n_rounds = max((c["round"] for c in rep.candidates), default=0)
    print(f"discrepancy workflow, 20-minute record at 80 Hz, {len(surrogates.EFFECTS)} candidate effects: "
          f"{wall:.1f} s wall ({n_rounds} greedy round(s)); target < 180 s")
    print(rep.summary())


if __name__ == "__main__":
    main()
