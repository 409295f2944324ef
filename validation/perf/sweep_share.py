#!/usr/bin/env python3
"""Serial share of `shpb sweep` in instructions (issue 45; validation/perf/sweep.md).

Runs one sweep under callgrind with one profile per thread (`--separate-threads=yes`). The
main thread does the serial part of a sweep: start, parsing, planning, and after the runs the
table and the output files; every run (and, since issue 45, the validation of the points) is
made on a pool thread. Since issue 45 the main thread also writes the study file's
`/runs/<index>` groups (`shpb_output::study::write_run_group`) while the runs go on: that work
overlaps the runs and counts as parallel work, except the last run's group, written after the
last run. So the serial part S = main-thread instructions − those groups + one group, the
serial share s = S / all instructions, and Amdahl's law gives the speed-up on P cores as
1 / (s + (1 − s) / P).

    python3 validation/perf/sweep_share.py BIN [POINTS] [JOBS]

BIN is the `shpb` binary; POINTS (256) runs of scenes/force-driven-ss440c-10psi.toml over
medium_impedance_kg_s from 1e4 to 1.2e4 kg/s; JOBS (1) threads; -o and --csv written.
"""

import glob
import os
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main() -> None:
    binary = sys.argv[1]
    points = int(sys.argv[2]) if len(sys.argv) > 2 else 256
    jobs = sys.argv[3] if len(sys.argv) > 3 else "1"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "cg.%p")
        cmd = [
            "valgrind", "--tool=callgrind", "--separate-threads=yes",
            f"--callgrind-out-file={out}",
            binary, "--quiet", "sweep", str(ROOT / "scenes/force-driven-ss440c-10psi.toml"),
            "--set", f"medium_impedance_kg_s=1.0e4:1.2e4:{points}", "-j", jobs,
            "-o", os.path.join(d, "s.h5"), "--csv", os.path.join(d, "s.csv"),
        ]
        subprocess.run(cmd, check=True, capture_output=True)
        threads = {}
        groups = 0
        for f in glob.glob(os.path.join(d, "cg.*-*")):
            text = pathlib.Path(f).read_text(errors="replace")
            tid = int(f.rsplit("-", 1)[1])
            threads[tid] = next(int(l.split()[1]) for l in text.splitlines() if l.startswith("totals:"))
            if tid == 1:
                annotated = subprocess.run(
                    ["callgrind_annotate", "--inclusive=yes", "--threshold=100", f],
                    check=True, capture_output=True, text=True,
                ).stdout
                for line in annotated.splitlines():
                    if "shpb_output::study::write_run_group " in line:
                        groups = int(line.split()[0].replace(",", ""))
    total = sum(threads.values())
    main = threads[1]
    serial = main - groups + groups / points
    s = serial / total
    print(f"points {points}, -j {jobs}: total {total / 1e6:.1f} M instructions, "
          f"main thread {main / 1e6:.2f} M of which run groups written during the runs "
          f"{groups / 1e6:.2f} M; serial {serial / 1e6:.2f} M, serial share {100 * s:.3f} %")
    for p in (2, 16, 64, 256):
        print(f"  Amdahl speed-up on {p} cores: {1 / (s + (1 - s) / p):.1f}x")


if __name__ == "__main__":
    main()
