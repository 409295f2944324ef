"""The Python package against the `shpb` binary: same numbers bit for bit, same files, same
errors (with the command line's message)."""

import json
import pathlib
import tomllib

import h5py
import numpy as np
import pytest

import shpb

from conftest import ROOT

SCENES = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "scenes").glob("*.toml"))
RECORD = "validation/gauge-records/data/2013-05-22_sample3_ss440c.csv"


def h5_datasets(path):
    """Every float dataset of an HDF5 file: path -> (array, units)."""
    out = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.dtype == np.float64:
            units = obj.attrs.get("units", "")
            out[name] = (obj[()], units.decode() if isinstance(units, bytes) else units)

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return out


def h5_summary(path):
    """The summary of a run file as a script reads it with h5py (README, HDF5 layout): the number
    attributes of /summary, and the items a dataset holds one per element (its attribute
    ``summary_key`` = ``NAME_<k>``: element k - 1 is ``NAME_k``, as ``/chain/final_velocity``
    holds a chain's ``final_velocity_<k>``, issue 45)."""
    with h5py.File(path, "r") as f:
        s = f["summary"]
        # Numbers only: the text attributes (units, warnings, alignment, verdict) are not items.
        out = {
            k: float(v)
            for k, v in s.attrs.items()
            if not isinstance(v, (str, bytes)) and k not in ("units", "warnings")
        }

        def per_element(name, obj):
            if isinstance(obj, h5py.Dataset) and "summary_key" in obj.attrs:
                key = obj.attrs["summary_key"]
                stem = (key.decode() if isinstance(key, bytes) else key).removesuffix("<k>")
                out.update({f"{stem}{k}": float(x) for k, x in enumerate(obj[()], 1)})

        f.visititems(per_element)
        return out


def same(a, b):
    """Bit-for-bit equality of two float arrays (NaN included)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def assert_runs_equal(r1, r2):
    assert r1.keys() == r2.keys()
    for k in r1.keys():
        assert same(r1[k], r2[k]), k
        assert r1.units[k] == r2.units[k], k
    assert r1.summary.keys() == r2.summary.keys()
    for k in r1.summary:
        assert same(r1.summary[k], r2.summary[k]), k


@pytest.mark.parametrize("scene", SCENES)
def test_each_scene_equals_the_binary_bit_for_bit(scene, cli, tmp_path):
    out = tmp_path / "cli.h5"
    cli("run", scene, "--fidelity", "fast", "-o", out)
    r = shpb.run(scene, fidelity="fast")
    file = h5_datasets(out)
    assert r.keys() == sorted(file)
    for k, (data, units) in file.items():
        assert same(r[k], data), k
        assert r.units[k] == units, k
    summary = h5_summary(out)
    assert set(r.summary) == set(summary)
    for k, v in summary.items():
        assert same(r.summary[k], v), k
    # The file read back is the same run.
    assert_runs_equal(shpb.load(out), r)


def test_a_driven_run_keeps_the_force_it_applied():
    # /drive/force: the recorded incident wave as the force on the impact end; on a bar at rest
    # its work is sum(F^2) dt / Z, the drive_work the bar's ledger recorded (docs/physics.md §6.10),
    # exactly so on an exact delay line (the scene's 1 mm cells; `fast`'s 4 mm ones do not divide
    # the 1.21 m bar, which then runs below Courant 1 and gives 3e-7).
    r = shpb.run("scenes/shpb-ss440c-record-driven.toml")
    t, f = r["drive/time"], r["drive/force"]
    assert r.units["drive/force"] == "N" and r.units["drive/time"] == "s"
    assert len(t) == len(f) and t[0] == 0.0
    bars = tomllib.loads((ROOT / "bars/authors.toml").read_text())
    m, d = bars["material"], bars["incident"]["diameter_m"]
    z = np.sqrt(m["youngs_modulus_pa"] * m["density_kg_m3"]) * np.pi * d * d / 4
    work = float(np.sum(f * f) * (t[1] - t[0]) / z)
    assert abs(work - r.summary["drive_work"]) <= 1e-9 * r.summary["drive_work"]


def test_save_writes_the_file_of_shpb_run(cli, tmp_path):
    scene = "scenes/shpb-ss440c-10psi.toml"
    cli("run", scene, "--fidelity", "fast", "-o", tmp_path / "cli.h5")
    r = shpb.run(scene, fidelity="fast")
    r.save(tmp_path / "py.h5")
    a, b = h5_datasets(tmp_path / "cli.h5"), h5_datasets(tmp_path / "py.h5")
    assert a.keys() == b.keys()
    for k in a:
        assert same(a[k][0], b[k][0]) and a[k][1] == b[k][1], k
    with h5py.File(tmp_path / "cli.h5") as f, h5py.File(tmp_path / "py.h5") as g:
        assert f.attrs["scene"] == g.attrs["scene"]
        assert f["summary"].attrs["units"] == g["summary"].attrs["units"]
        assert f["summary"].attrs["warnings"] == g["summary"].attrs["warnings"]
        for name in ("scene_file", "fidelity_override"):
            assert f["provenance"].attrs[name] == g["provenance"].attrs[name]
        assert list(f["provenance/input_names"]) == list(g["provenance/input_names"])
        assert list(f["provenance/input_texts"]) == list(g["provenance/input_texts"])
        assert "shpb.run" in g["provenance"].attrs["command_line"]


def test_load_of_save_round_trips(tmp_path):
    r = shpb.run("scenes/shpb-ss440c-10psi.toml", fidelity="fast", set={"pressure": "12psi"})
    r.save(tmp_path / "run.h5")
    back = shpb.load(tmp_path / "run.h5")
    assert back.origin == "file"
    assert_runs_equal(back, r)
    assert back.warnings == r.warnings
    assert back.scene == r.scene
    assert back.provenance["inputs"] == r.provenance["inputs"]
    # A loaded run saves a copy of its file.
    back.save(tmp_path / "copy.h5")
    assert (tmp_path / "copy.h5").read_bytes() == (tmp_path / "run.h5").read_bytes()


def test_set_overrides_like_the_scene_file_and_the_saved_file_reruns(cli, tmp_path):
    text = (ROOT / "scenes/shpb-ss440c-10psi.toml").read_text().replace('"10psi"', '"12psi"')
    (tmp_path / "scenes").mkdir()
    scene = tmp_path / "scenes" / "s.toml"
    scene.write_text(text)
    (tmp_path / "bars").symlink_to(ROOT / "bars")
    direct = shpb.run(scene, fidelity="fast")
    overridden = shpb.run("scenes/shpb-ss440c-10psi.toml", fidelity="fast", set={"pressure": "12psi"})
    assert_runs_equal(direct, overridden)
    assert overridden.summary["pressure"] != shpb.run(
        "scenes/shpb-ss440c-10psi.toml", fidelity="fast"
    ).summary["pressure"]
    # The saved file stores the overridden scene: `shpb run FILE.h5` and shpb.run(FILE.h5) rerun it.
    overridden.save(tmp_path / "run.h5")
    cli("run", tmp_path / "run.h5", "-o", tmp_path / "rerun.h5")
    assert h5_summary(tmp_path / "rerun.h5") == overridden.summary
    assert_runs_equal(shpb.run(tmp_path / "run.h5"), overridden)


def test_a_dict_scene_equals_the_toml_scene():
    scene = {
        "kind": "collision",
        "law": "burgoyne-daraio",
        "velocity1_m_s": 5.0,
        "velocity2_m_s": 0.0,
        "specimen": {"pair": "ss440c"},
    }
    assert_runs_equal(shpb.run(scene), shpb.run("scenes/collision-ss440c-5ms.toml"))
    # Relative paths of a dict are relative to the working directory.
    bar_scene = {
        "kind": "shpb",
        "bars": "bars/authors.toml",
        "pressure": "10psi",
        "law": "burgoyne-daraio",
        "specimen": {"pair": "ss440c"},
    }
    assert_runs_equal(
        shpb.run(bar_scene, fidelity="fast"),
        shpb.run("scenes/shpb-ss440c-10psi.toml", fidelity="fast"),
    )


def test_a_chain_scene_runs_from_python_with_the_numbers_of_the_cli(cli):
    """Issue 17: a `chain` scene through `shpb.run` (file and dict) gives the summary the
    command line prints (`--json`) and the /chain datasets, contact × time and sphere × time."""
    import json

    scene = "scenes/chain-ss440c-10.toml"
    r = shpb.run(scene)
    printed = json.loads(cli("run", scene, "--json").stdout)["summary"]
    assert set(r.summary) == set(printed)
    for k, v in printed.items():
        assert r.summary[k] == v["value"], k
    t = r["chain/time"]
    assert r["chain/contact_force"].shape == (9, t.size)
    assert r["chain/contact_approach"].shape == (9, t.size)
    assert r["chain/velocity"].shape == (10, t.size)
    assert (r.units["chain/contact_force"], r.units["chain/velocity"]) == ("N", "m/s")
    # Momentum of the free chain: sphere 1's initial 5 m/s shared by ten equal spheres.
    assert abs(r["chain/final_velocity"].sum() - 5.0) < 1e-10
    scene_dict = {
        "kind": "chain",
        "law": "burgoyne-daraio",
        "velocity1_m_s": 5.0,
        "end_time_s": 75e-6,
        "specimen": {"count": 10, "material": "ss440c", "diameter_m": 6.35e-3},
    }
    assert_runs_equal(shpb.run(scene_dict), r)


def test_a_saved_dict_scene_reruns_from_its_file(cli, tmp_path):
    r = shpb.run({"kind": "collision", "velocity1_m_s": 3.0, "specimen": {"pair": "ss440c"}})
    r.save(tmp_path / "d.h5")
    cli("run", tmp_path / "d.h5", "-o", tmp_path / "rerun.h5")
    assert h5_summary(tmp_path / "rerun.h5") == r.summary


def test_gun_and_curve_are_the_commands(cli):
    out = cli("gun", "--pressure", "10psi").stdout
    line = next(l for l in out.splitlines() if l.startswith("striker velocity"))
    assert f"{shpb.gun('10psi', bars='authors'):.4f}" in line
    assert shpb.gun(68947.5729) == pytest.approx(shpb.gun("10psi"), rel=1e-9)
    delta, force = shpb.curve("ss440c", rate=1000.0, to=250e-6, points=101)
    text = cli("curve", "--specimen", "ss440c", "--rate", "1000", "--to", "250e-6", "--points", "101").stdout
    table = np.array([[float(x) for x in l.split(",")] for l in text.splitlines()[1:]])
    assert same(table[:, 0], delta) and same(table[:, 1], force)


def test_reduce_equals_shpb_reduce(cli, tmp_path):
    cli("reduce", RECORD, "--bars", "authors", "-o", tmp_path / "red.h5")
    r = shpb.reduce(RECORD, bars="authors")
    file = h5_datasets(tmp_path / "red.h5")
    assert r.keys() == sorted(file)
    for k, (data, units) in file.items():
        assert same(r[k], data) and r.units[k] == units, k
    assert r.summary == h5_summary(tmp_path / "red.h5")
    assert "reduction/force_back" in r
    r.save(tmp_path / "py.h5")
    assert_runs_equal(shpb.load(tmp_path / "py.h5"), r)


def test_reduce_dispersion_keyword_equals_the_flags(cli, tmp_path):
    # dispersion= takes the names of `shpb reduce --dispersion`; True/False are the old form.
    cli(
        "reduce", RECORD, "--bars", "authors", "-o", tmp_path / "pc.h5",
        "--dispersion", "pochhammer-chree", "--tyas-pope",
    )
    r = shpb.reduce(RECORD, bars="authors", dispersion="pochhammer-chree", tyas_pope=True)
    for k, (data, units) in h5_datasets(tmp_path / "pc.h5").items():
        assert same(r[k], data), k
    off = shpb.reduce(RECORD, bars="authors", dispersion="none")
    old = shpb.reduce(RECORD, bars="authors", dispersion=False)
    assert same(off["reduction/force_back"], old["reduction/force_back"])
    with pytest.raises(shpb.InputError):
        shpb.reduce(RECORD, dispersion="love")


def test_reduce_of_a_cylinder_equals_shpb_reduce_and_recovers_its_modulus(cli, tmp_path):
    """A cylinder's run file reduced with its geometry (docs/physics.md §7.8): the same curves as
    `shpb reduce --specimen-length --specimen-diameter`, and the 3-wave modulus fitted on 30-90 %
    of the loading part within 1 % of the scene's material (crates/cli/tests/cylinder.rs)."""
    import tomllib

    scene = "scenes/shpb-cylinder-al.toml"
    spec = tomllib.loads((ROOT / scene).read_text())["specimen"]
    material = tomllib.loads((ROOT / "specimens" / f"{spec['material']}.toml").read_text())
    length, diameter = spec["length_m"], spec["diameter_m"]
    run = tmp_path / "run.h5"
    cli("run", scene, "-o", run)
    geometry = ["--specimen-length", repr(length), "--specimen-diameter", repr(diameter)]
    cli("reduce", run, "--no-dispersion", *geometry, "-o", tmp_path / "red.h5")
    r = shpb.reduce(run, dispersion=False, specimen_length_m=length, specimen_diameter_m=diameter)
    file = h5_datasets(tmp_path / "red.h5")
    assert r.keys() == sorted(file)
    for k, (data, units) in file.items():
        assert same(r[k], data) and r.units[k] == units, k
    assert r.summary == h5_summary(tmp_path / "red.h5")
    assert r.units["reduction/cylinder/one_wave/stress"] == "Pa"
    stress = r["reduction/cylinder/three_wave/stress"]
    strain = r["reduction/cylinder/three_wave/strain"]
    k = int(np.argmax(stress))
    peak = stress[k]
    first = int(np.argmax(stress[: k + 1] >= 0.3 * peak))
    last = int(np.nonzero(stress[: k + 1] <= 0.9 * peak)[0][-1])
    slope = np.polyfit(strain[first : last + 1], stress[first : last + 1], 1)[0]
    assert abs(slope / material["youngs_modulus_pa"] - 1) < 0.01
    # Both keywords or neither, as the flags.
    code, message = cli_message(cli, "reduce", run, "--specimen-length", "6e-3")
    with pytest.raises(shpb.InputError) as e:
        shpb.reduce(run, specimen_length_m=6e-3)
    assert "`specimen_diameter_m`: missing" in str(e.value)
    assert "missing" in message and code == 2


def test_reduce_alignment_and_smoothing_keywords_equal_the_flags(cli, tmp_path):
    # align= and smooth= take the values of `shpb reduce --align/--smooth`: the same datasets.
    cli(
        "reduce", RECORD, "--bars", "authors", "-o", tmp_path / "foot.h5",
        "--align", "foot", "--smooth", "0",
    )
    r = shpb.reduce(RECORD, bars="authors", align="foot", smooth=0.0)
    for k, (data, units) in h5_datasets(tmp_path / "foot.h5").items():
        assert same(r[k], data), k
    with pytest.raises(shpb.InputError):
        shpb.reduce(RECORD, align="auto")


def test_reduce_balance_bound_keyword_equals_the_flag(cli, tmp_path):
    # balance_bound_s= is `--balance-bound`: the same windows, the same datasets, the same error.
    cli(
        "reduce", RECORD, "--bars", "authors", "-o", tmp_path / "b.h5",
        "--align", "balance", "--balance-bound", "3e-5",
    )
    r = shpb.reduce(RECORD, bars="authors", align="balance", balance_bound_s=3e-5)
    for k, (data, units) in h5_datasets(tmp_path / "b.h5").items():
        assert same(r[k], data), k
    code, message = cli_message(cli, "reduce", RECORD, "--balance-bound", "0")
    with pytest.raises(shpb.InputError) as e:
        shpb.reduce(RECORD, balance_bound_s=0.0)
    assert "`--balance-bound`" in str(e.value) and "`--balance-bound`" in message
    assert code == 2


def test_sweep_in_parallel_equals_serial():
    kw = dict(set={"pressure": ["8psi", "10psi", "12psi"]})
    scene = "scenes/shpb-ss440c-10psi.toml"
    t1 = shpb.sweep(scene, jobs=1, **kw)
    t2 = shpb.sweep(scene, jobs=2, **kw)
    assert t1.keys() == t2.keys()
    for k in t1.keys():
        assert same(t1[k], t2[k]), k
    assert t1.units["peak_force"] == "N" and t1.units["pressure"] == "Pa"
    assert same(t1.inputs["pressure"], [shpb.run(scene, set={"pressure": p}).summary["pressure"] for p in kw["set"]["pressure"]])
    # Each row is the run of its point.
    r = shpb.run(scene, set={"pressure": "12psi"})
    assert same(t1["peak_force"][2], r.summary["peak_contact_force"])
    # The (and a run's) name for the column reads the same array.
    assert t1["peak_contact_force"] is t1["peak_force"]


def test_run_gives_the_bands_of_shpb_run_json(cli, tmp_path):
    # bars/authors.toml states [uncertainty]: the 90 % bands, as `shpb run --json` writes them.
    scene = "scenes/shpb-ss440c-10psi.toml"
    out = tmp_path / "r.h5"
    j = json.loads(cli("--json", "run", scene, "--fidelity", "fast", "-o", out).stdout)
    r = shpb.run(scene, fidelity="fast")
    banded = {k: v for k, v in j["summary"].items() if "band_90" in v}
    assert "incident_peak_stress" in banded and "transmitted_delay" in banded
    assert r.bands == banded
    for k, v in banded.items():
        lo, hi = v["band_90"]
        assert lo <= v["value"] <= hi, k
    assert shpb.load(out).bands == banded
    assert shpb.run(scene, fidelity="fast", bands=False).bands == {}


def test_a_sweep_table_keeps_each_run_s_warnings(cli):
    scene = "scenes/shpb-ss440c-10psi.toml"
    t = shpb.sweep(scene, set={"pressure": ["8psi", "10psi"]}, fidelity="fast")
    # (shpb.sweep names the scene by its absolute path, and so the set-up in its warnings.)
    run = json.loads(
        cli(
            "--json", "run", ROOT / scene, "--set", "pressure=8psi", "--fidelity", "fast", "--no-bands"
        ).stdout
    )
    assert run["warnings"] and t.warnings[0] == run["warnings"]
    assert t.warnings[1] == []


# --- errors: the exception of the exit code, with the command line's message ---------------


def test_reduce_specimen_keyword_equals_the_flag(cli, tmp_path):
    # specimen= is `shpb reduce --specimen`: the same datasets; 12.7 mm spheres halve the rate
    # of the default 6.35 mm ones exactly; a bad file names its key, as the flag's message.
    big = tmp_path / "big.toml"
    big.write_text('[specimen]\ncount = 2\nmaterial = "ss440c"\ndiameter_m = 12.7e-3\n')
    cli("reduce", RECORD, "--bars", "authors", "-o", tmp_path / "big.h5", "--specimen", big)
    r = shpb.reduce(RECORD, bars="authors", specimen=big)
    for k, (data, units) in h5_datasets(tmp_path / "big.h5").items():
        assert same(r[k], data), k
    small = shpb.reduce(RECORD, bars="authors")
    assert np.array_equal(r["reduction/strain_rate"], small["reduction/strain_rate"] / 2)
    bad = tmp_path / "bad.toml"
    bad.write_text('[specimen]\nshape = "cube"\n')
    code, message = cli_message(cli, "reduce", RECORD, "--specimen", bad)
    with pytest.raises(shpb.InputError) as e:
        shpb.reduce(RECORD, specimen=bad)
    assert "`specimen.shape`" in str(e.value) and "`specimen.shape`" in message
    assert code == 2


def cli_message(cli, *args):
    p = cli(*args, check=False)
    assert p.returncode != 0
    return p.returncode, p.stderr.split("shpb: error: ", 1)[1].strip()


BAD_SCENES = {
    "unknown-kind.toml": 'kind = "bogus"\n',
    "missing-kind.toml": "velocity1_m_s = 5.0\n",
    "syntax.toml": "kind = \n",
    "out-of-range.toml": 'kind = "collision"\nvelocity1_m_s = -5.0\n[specimen]\npair = "ss440c"\n',
    "unknown-pair.toml": 'kind = "collision"\nvelocity1_m_s = 5.0\n[specimen]\npair = "unobtainium"\n',
    "bad-fidelity.toml": 'kind = "collision"\nvelocity1_m_s = 5.0\nfidelity = "ultra"\n[specimen]\npair = "ss440c"\n',
    "missing-bars.toml": 'kind = "shpb"\nbars = "nope.toml"\npressure = "10psi"\n[specimen]\npair = "ss440c"\n',
    "bad-pressure.toml": 'kind = "shpb"\nbars = "authors"\npressure = "10 parsecs"\n[specimen]\npair = "ss440c"\n',
}


@pytest.mark.parametrize("name", sorted(BAD_SCENES))
def test_bad_scenes_raise_input_error_with_the_cli_message(name, cli, tmp_path):
    path = tmp_path / name
    path.write_text(BAD_SCENES[name])
    code, message = cli_message(cli, "run", path)
    assert code == 2
    with pytest.raises(shpb.InputError) as e:
        shpb.run(path)
    assert str(e.value).strip() == message
    assert isinstance(e.value, ValueError)


CORPUS = sorted((ROOT / "tests/corpus/bad").glob("*.toml"))


@pytest.mark.parametrize("path", CORPUS, ids=[p.name for p in CORPUS])
def test_the_bad_input_corpus_raises_the_exception_of_its_exit_code(path, cli):
    """Every scene of `tests/corpus/bad/` (also run by the Rust CLI tests): the exception of
    the exit code its first line expects (2: InputError), with exactly the CLI's message."""
    expect = path.read_text().splitlines()[0].removeprefix("# expect: ")
    code, fragment = expect.split(" | ", 1)
    cli_code, message = cli_message(cli, "run", path)
    assert cli_code == int(code) == 2
    with pytest.raises(shpb.InputError) as e:
        shpb.run(path)
    assert str(e.value).strip() == message
    assert fragment in message


def test_a_missing_scene_is_an_os_error(cli):
    code, message = cli_message(cli, "run", "no/such/scene.toml")
    with pytest.raises(FileNotFoundError) as e:
        shpb.run("no/such/scene.toml")
    assert e.value.strerror == message
    assert isinstance(e.value, OSError)


def test_other_bad_inputs_raise_input_error(cli, tmp_path):
    with pytest.raises(shpb.InputError):
        shpb.run("scenes/collision-ss440c-5ms.toml", fidelity="ultra")
    with pytest.raises(shpb.InputError):
        shpb.run("scenes/shpb-ss440c-10psi.toml", set={"pressure": "ten psi"})
    with pytest.raises(shpb.InputError):
        shpb.run({"kind": "collision", "velocity1_m_s": object()})
    code, message = cli_message(cli, "gun", "--pressure", "10parsec")
    with pytest.raises(shpb.InputError, match="--pressure") as e:
        shpb.gun("10parsec")
    assert str(e.value).strip() == message
    code, message = cli_message(cli, "gun", "--pressure", "10psi", "--bars", "nope")
    with pytest.raises(shpb.InputError) as e:
        shpb.gun("10psi", bars="nope")
    assert str(e.value).strip() == message
    code, message = cli_message(cli, "curve", "--points", "1")
    with pytest.raises(shpb.InputError) as e:
        shpb.curve(points=1)
    assert str(e.value).strip() == message
    with pytest.raises(shpb.InputError):
        shpb.curve(law="nope")
    code, message = cli_message(cli, "reduce", "no-such-record.csv")
    with pytest.raises(shpb.InputError) as e:
        shpb.reduce("no-such-record.csv")
    assert str(e.value).strip() == message
    with pytest.raises(shpb.InputError):
        shpb.sweep("scenes/shpb-ss440c-10psi.toml", set={"pressure": []})
    with pytest.raises(shpb.InputError):
        shpb.load(ROOT / "README.md")
    with pytest.raises(KeyError):
        shpb.run("scenes/collision-ss440c-5ms.toml")["no/such/dataset"]


def test_save_refuses_an_existing_file_and_a_wrong_extension(tmp_path):
    r = shpb.run("scenes/collision-ss440c-5ms.toml")
    r.save(tmp_path / "a.h5")
    with pytest.raises(shpb.InputError, match="exists"):
        r.save(tmp_path / "a.h5")
    r.save(tmp_path / "a.h5", force=True)
    with pytest.raises(shpb.InputError):
        r.save(tmp_path / "a.csv")


def test_instability_error_is_a_runtime_error():
    assert issubclass(shpb.InstabilityError, RuntimeError)
    assert issubclass(shpb.InputError, ValueError)


def test_summary_html_and_units():
    r = shpb.run("scenes/shpb-ss440c-10psi.toml", fidelity="fast")
    assert r.units["contact/force"] == "N"
    assert r.units["peak_contact_force"] == "N"
    assert isinstance(r.summary["peak_contact_force"], float)
    html = r._repr_html_()
    assert "peak_contact_force" in html and "<table>" in html
    assert r["summary/peak_contact_force"].shape == ()
    snap = r["bars/incident/snapshots"]
    assert snap.ndim == 2 and snap.shape == (len(r["bars/incident/time"]), len(r["bars/incident/x"]))


def test_ctrl_c_stops_a_long_run_cleanly():
    """SIGINT during a run raises KeyboardInterrupt within about 1 % of the run, and the
    interpreter (and the next run) carry on normally. The signal is sent every 0.2 s until the
    run stops (one sent while the scene is still being read is only seen when the run starts);
    signals after the first interrupt are ignored by the test's handler."""
    import os
    import signal
    import threading
    import time

    stopped = threading.Event()
    seen = []

    def handler(signum, frame):
        if not seen:
            seen.append(time.monotonic())
            raise KeyboardInterrupt

    def send():
        while not stopped.wait(0.2):
            os.kill(os.getpid(), signal.SIGINT)

    previous = signal.signal(signal.SIGINT, handler)
    sender = threading.Thread(target=send, daemon=True)
    start = time.monotonic()
    sender.start()
    try:
        with pytest.raises(KeyboardInterrupt, match="interrupted at step"):
            # The Love-rod chain at 0.125 mm takes several seconds: stopped long before its end.
            shpb.run(
                "scenes/shpb-ss440c-10psi.toml",
                set={"dispersion": "love-rod", "cell_size_m": "0.125mm"},
            )
    finally:
        stopped.set()
        sender.join()
        signal.signal(signal.SIGINT, previous)
    assert seen and time.monotonic() - start < 3.0
    r = shpb.run("scenes/collision-ss440c-5ms.toml", fidelity="fast")
    assert r.summary["restitution"] > 0


def test_sweep_fidelity_is_the_command_s_flag(cli, tmp_path):
    """``fidelity=`` is ``shpb sweep --fidelity``: the table of ``set={"fidelity": [...]}``
    (its ``fidelity`` column included), each row the run at that preset, the command's CSV
    value for value; the key given both ways is refused, naming it."""
    scene = "scenes/shpb-ss440c-10psi.toml"
    grid = {"pressure": ["9psi", "11psi"]}
    flag = shpb.sweep(scene, set=grid, fidelity="fast")
    axis = shpb.sweep(scene, set={**grid, "fidelity": ["fast"]})
    assert flag.keys() == axis.keys() and "fidelity" in flag.keys_swept
    for k in flag.keys():
        assert same(flag[k], axis[k]), k
    r = shpb.run(scene, fidelity="fast", set={"pressure": "11psi"})
    assert same(flag["peak_force"][1], r.summary["peak_contact_force"])
    assert not same(flag["peak_force"][1], shpb.run(scene, set={"pressure": "11psi"}).summary["peak_contact_force"])
    out = tmp_path / "fast.csv"
    cli("sweep", scene, "--set", "pressure=9psi,11psi", "--fidelity", "fast", "--csv", out)
    head, *rows = [line.split(",") for line in out.read_text().splitlines()]
    column = [float(row[head.index("peak_force_N")]) for row in rows]
    assert same(list(flag["peak_force"]), column)
    with pytest.raises(shpb.InputError, match="fidelity"):
        shpb.sweep(scene, set={**grid, "fidelity": ["standard"]}, fidelity="fast")


def test_a_sweep_too_large_for_the_machine_is_refused_before_it_allocates():
    """As `shpb sweep`: 10^10 runs are refused with the estimate and the limit (InputError)."""
    grid = {"pressure": "7psi:22psi:100000", "shaper.thickness_m": "0.1mm:1mm:100000"}
    with pytest.raises(shpb.InputError, match="cannot finish on this machine: 10000000000 runs"):
        shpb.sweep("scenes/shpb-ss440c-10psi.toml", set=grid)


def test_an_unstable_run_raises_instability_error_with_the_cli_message(cli, tmp_path):
    """A collision of spheres so soft (σy = 10 kPa) that the contact outlasts the solver's
    limit of 100 Hertz contact times ends as exit 3 in the CLI and InstabilityError in Python,
    with the same message."""
    soft = (ROOT / "specimens/ss440c.toml").read_text()
    soft = soft.replace("yield_stress_pa = 1900e6", "yield_stress_pa = 1e4")
    (tmp_path / "soft.toml").write_text(soft)
    sphere = {"material": str(tmp_path / "soft.toml"), "diameter_m": 6.35e-3}
    scene = {
        "kind": "collision",
        "velocity1_m_s": 5.0,
        "law": "rate-independent",
        "fidelity": "fast",
        "specimen": {"sphere1": sphere, "sphere2": sphere},
    }
    with pytest.raises(shpb.InstabilityError) as err:
        shpb.run(scene)
    assert "contact did not end before the time limit" in str(err.value)
    text = "\n".join(
        [
            'kind = "collision"',
            "velocity1_m_s = 5.0",
            'law = "rate-independent"',
            'fidelity = "fast"',
            "[specimen.sphere1]",
            f'material = "{tmp_path / "soft.toml"}"',
            "diameter_m = 6.35e-3",
            "[specimen.sphere2]",
            f'material = "{tmp_path / "soft.toml"}"',
            "diameter_m = 6.35e-3",
            "",
        ]
    )
    (tmp_path / "soft-collision.toml").write_text(text)
    code, message = cli_message(cli, "run", tmp_path / "soft-collision.toml")
    assert code == 3
    assert message == str(err.value)


def test_plot_draws_the_three_panels_or_says_what_is_missing(tmp_path):
    """`Run.plot()`: with matplotlib, the three panels of a full test (F–δ, gauges, reduced
    forces); without it, an ImportError that says how to get it."""
    r = shpb.run("scenes/shpb-ss440c-10psi.toml", fidelity="fast")
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError:
        with pytest.raises(ImportError, match="pip install matplotlib"):
            r.plot()
        return
    fig = r.plot(tmp_path / "run.png")
    assert len(fig.axes) == 3
    assert (tmp_path / "run.png").stat().st_size > 0
    # An existing figure is kept unless force=True, and nothing but the figure is left.
    (tmp_path / "run.png").write_bytes(b"old")
    with pytest.raises(FileExistsError, match="pass force=True"):
        r.plot(tmp_path / "run.png")
    assert (tmp_path / "run.png").read_bytes() == b"old"
    r.plot(tmp_path / "run.png", force=True)
    assert (tmp_path / "run.png").read_bytes() != b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.png"]


def test_plot_refuses_an_existing_file_before_drawing(tmp_path):
    """`Run.plot(path)` keeps an existing file unless force, whether or not matplotlib is there
    (the check comes first, as the command line's does)."""
    r = shpb.run("scenes/collision-ss440c-5ms.toml", fidelity="fast")
    (tmp_path / "old.png").write_bytes(b"old")
    with pytest.raises(FileExistsError, match="output file exists"):
        r.plot(tmp_path / "old.png")
    assert (tmp_path / "old.png").read_bytes() == b"old"


def test_a_run_shows_its_summary_as_a_table_in_jupyter():
    r = shpb.run("scenes/collision-ss440c-5ms.toml", fidelity="fast")
    page = r._repr_html_()
    assert "<table" in page and "restitution" in page


def _records(tmp_path):
    """Bad gauge records: inverted polarity, a binary file, a missing column."""
    source = (ROOT / "validation/gauge-records/data/2013-05-22_sample2_ss440c.csv").read_text()
    lines = source.splitlines()
    out = []
    for line in lines:
        cells = line.split(",")
        if line.startswith("#") or not cells[0][:1].isdigit() and not cells[0][:1] == "-":
            out.append(line)
        else:
            out.append(",".join([cells[0]] + [repr(-float(c)) for c in cells[1:]]))
    inverted = tmp_path / "inverted.csv"
    inverted.write_text("\n".join(out) + "\n")
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"time_s,incident_V,transmission_V\n\x00\x01\xff\n")
    missing = tmp_path / "missing-column.csv"
    missing.write_text("time_s,incident_V\n0,0\n1e-7,0\n")
    return [inverted, binary, missing]


def test_bad_records_raise_input_error_with_the_cli_message(cli, tmp_path):
    for record in _records(tmp_path):
        code, message = cli_message(cli, "reduce", record)
        assert code == 2, record
        with pytest.raises(shpb.InputError) as e:
            shpb.reduce(record)
        assert str(e.value).strip() == message, record


def test_reduce_layout_keyword_equals_the_flag(cli, tmp_path):
    # A record in the authors' LabVIEW layout (four tab-separated columns, no header), written
    # from the CSV, reduced by `shpb reduce --layout` and by shpb.reduce(layout=): the same
    # datasets, and the same numbers as the CSV itself.
    rows = [
        l.split(",")
        for l in (ROOT / RECORD).read_text().splitlines()
        if l and not l.startswith("#") and not l.startswith("time_s")
    ]
    lvm = tmp_path / "record.lvm"
    lvm.write_text("".join(f"{t}\t{i}\t{t}\t{tr}\n" for t, i, tr in rows))
    layout = ROOT / "layouts" / "authors-lvm.toml"
    cli("reduce", lvm, "--layout", layout, "--bars", "authors", "-o", tmp_path / "lvm.h5")
    r = shpb.reduce(lvm, bars="authors", layout=layout)
    for k, (data, units) in h5_datasets(tmp_path / "lvm.h5").items():
        assert same(r[k], data), k
    csv = shpb.reduce(RECORD, bars="authors")
    assert same(r["reduction/force_back"], csv["reduction/force_back"])


def test_reduce_verdict_is_the_sentence_shpb_reduce_writes(cli):
    # Run.verdict is (verdict, reason) as `shpb reduce --json` gives them.
    out = json.loads(cli("reduce", RECORD, "--align", "balance", "--json").stdout)
    r = shpb.reduce(RECORD, align="balance")
    verdict, reason = r.verdict
    assert reason == out["verdict_reason"]
    assert verdict in ("equilibrium", "marginal", "not in equilibrium")
    assert "balance" in reason
