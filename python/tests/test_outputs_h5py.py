"""Every HDF5 file the `shpb` binary writes reads with h5py, as a user's notebook would read it
(issue 15): run and rerun files, reductions of a record and of a run, strain files, sweep study
files and merged shards. Each dataset is read whole; numeric ones carry units (a study column
may hold NaN where a quantity does not apply, e.g. equilibrium in a free collision), text ones
decode as UTF-8."""

import h5py
import numpy as np


def read_everything(path):
    seen = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            data = obj[()]
            if obj.dtype.kind == "f":
                assert "units" in obj.attrs, f"{path}:{name} has no units"
                assert not np.any(np.isinf(data)), f"{path}:{name} is infinite"
            elif obj.dtype.kind == "O":
                for item in np.atleast_1d(data):
                    (item.decode() if isinstance(item, bytes) else str(item))
            seen.append(name)
        for key, value in obj.attrs.items():
            value.decode() if isinstance(value, bytes) else value

    with h5py.File(path, "r") as f:
        for value in f.attrs.values():
            value.decode() if isinstance(value, bytes) else value
        f.visititems(visit)
    assert seen, f"{path} holds no dataset"
    return seen


def test_h5py_reads_every_output(cli, tmp_path):
    record = "validation/gauge-records/data/2013-05-22_sample1_ss440c.csv"
    run, again = tmp_path / "run.h5", tmp_path / "again.h5"
    cli("run", "scenes/shpb-ss440c-10psi.toml", "--fidelity", "fast", "-o", run)
    cli("run", run, "-o", again)
    cli("reduce", run, "-o", tmp_path / "reduced-run.h5")
    cli("reduce", record, "-o", tmp_path / "reduced-record.h5")
    cli("strain", record, "-o", tmp_path / "strain.h5")
    sweep = ["sweep", "scenes/collision-ss440c-5ms.toml", "--set", "velocity1_m_s=1,2,3"]
    cli(*sweep, "-o", tmp_path / "study.h5")
    cli(*sweep, "--shard", "1/2", "-o", tmp_path / "shard1.h5")
    cli(*sweep, "--shard", "2/2", "-o", tmp_path / "shard2.h5")
    cli("merge", tmp_path / "shard1.h5", tmp_path / "shard2.h5", "-o", tmp_path / "merged.h5")
    files = sorted(tmp_path.glob("*.h5"))
    assert len(files) == 9
    for path in files:
        read_everything(path)
    # The run file describes itself: provenance, per-value units, time origins.
    with h5py.File(run, "r") as f:
        assert f["summary/peak_contact_force"].attrs["units"] in ("N", b"N")
        assert "origin" in f["reduction/time"].attrs
        names = [n.decode() if isinstance(n, bytes) else n for n in f["provenance/input_names"][()]]
        assert "scenes/shpb-ss440c-10psi.toml" in names
