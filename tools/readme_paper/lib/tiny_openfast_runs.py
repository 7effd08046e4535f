"""--tiny only: copies of the three turbulent shared OpenFAST runs cut to their first SECONDS (plumbing tests of
tools/openfast_table7.py, whose records are otherwise 600 s each). Usage: tiny_openfast_runs.py RUNS OUT SECONDS"""

import shutil
import sys
from pathlib import Path

from fowt_env.io import load_record, write_openfast

RUNS = ("c_op08_Hs2p0_Tp9", "c_op12_Hs2p5_Tp10", "c_op18_Hs4p0_Tp11")

src, dst, seconds = Path(sys.argv[1]), Path(sys.argv[2]), float(sys.argv[3])
for r in RUNS:
    rec = load_record(src / r / f"{r}.outb")
    keep = rec.t <= rec.t[0] + seconds
    short = type(rec)(rec.t[keep], rec.y[keep], rec.channels, rec.units, rec.meta)
    (dst / r).mkdir(parents=True, exist_ok=True)
    write_openfast(short, dst / r / f"{r}.outb")
    for extra in (f"{r}.case.json",):
        if (src / r / extra).is_file():
            shutil.copy(src / r / extra, dst / r / extra)
    print(f"{r}: {keep.sum()} samples -> {dst / r}")
