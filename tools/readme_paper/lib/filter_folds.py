"""Copy an earlier tools/openfast_table7.py run's fold_*.json without its Kalman runs (kalman, kalman_nogate,
kalman_nominal), for --merge with freshly measured Kalman folds: the tool's --merge concatenates the runs of every
folder per fold, so Kalman runs present in both would be counted twice. Usage: filter_folds.py SRC_DIR DST_DIR"""

import json
import sys
from pathlib import Path

KALMAN = {"kalman", "kalman_nogate", "kalman_nominal"}
src, dst = Path(sys.argv[1]), Path(sys.argv[2])
folds = sorted(src.glob("fold_*.json"))
if not folds:
    raise SystemExit(f"filter_folds: no fold_*.json in {src}")
dst.mkdir(parents=True, exist_ok=True)
for path in folds:
    fold = json.loads(path.read_text())
    kept = [r for r in fold["runs"] if r["estimator"] not in KALMAN]
    dropped = len(fold["runs"]) - len(kept)
    fold["runs"] = kept
    (dst / path.name).write_text(json.dumps(fold, indent=1))
    print(
        f"{path.name}: kept {len(kept)} runs ({sorted({r['estimator'] for r in kept})}), dropped {dropped} Kalman runs"
    )
