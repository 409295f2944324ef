"""shpb: a split Hopkinson pressure bar simulator, from Python.

The same Rust core as the ``shpb`` command line (``shpb._shpb``); no physics is written in Python.
Every quantity is a float in SI units, every series a numpy float64 array::

    import shpb
    r = shpb.run("scenes/shpb-ss440c-10psi.toml", fidelity="fast", set={"pressure": "12psi"})
    r.summary["peak_contact_force"]      # N
    r.units["contact/force"]             # "N"
    r["contact/force"]                   # numpy array
    r.save("out.h5")                     # the file `shpb run -o out.h5` writes

Errors carry the command line's message: :class:`InputError` (a ``ValueError``) for bad input
(exit code 2 of ``shpb``), :class:`InstabilityError` (a ``RuntimeError``) for an unstable run
(exit code 3), ``OSError`` for I/O failures.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import html
import json
import os
import time
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _shpb
from ._shpb import InputError, InstabilityError

__all__ = [
    "InputError",
    "InstabilityError",
    "Run",
    "Table",
    "run",
    "load",
    "gun",
    "curve",
    "reduce",
    "sweep",
    "study",
    "Study",
    "fit",
    "Fit",
    "__version__",
]

__version__: str = _shpb.version()

PathLike = Union[str, "os.PathLike[str]"]


class Run:
    """One run: a simulated test (:func:`run`), a reduction (:func:`reduce`) or a file read back
    (:func:`load`).

    ``run[path]`` is the dataset ``path`` of the run file (``"contact/force"``, ``"time"``,
    ``"gauges/incident/strain"``, ``"reduction/force_back"``, ``"summary/peak_contact_force"``)
    as a numpy float64 array; :meth:`keys` lists them all, :attr:`units` gives their units.
    """

    def __init__(self, data: "_shpb.RunData") -> None:
        self._data = data
        self._info = {p: (tuple(shape), unit) for p, shape, unit in data.dataset_info()}
        items = data.summary()
        self.summary: Dict[str, float] = {k: v for k, v, _ in items}
        """Scalar results (key → value in SI units), in the order ``shpb run`` prints them."""
        units = {p: u for p, (_, u) in self._info.items()}
        units.update({k: u for k, _, u in items})
        self.units: Dict[str, str] = units
        """Units of every dataset path and summary key."""
        self.bands: Dict[str, Dict[str, Any]] = {
            k: {"value": v, "unit": u, "band_90": [lo, hi]} for k, v, u, lo, hi in data.bands()
        }
        """The 90 % bands the set-up's ``[uncertainty]`` gives summary values (key →
        ``{"value", "unit", "band_90": [low, high]}``, as ``shpb run --json`` writes them;
        docs/physics.md §10.6); empty without one, or with ``run(..., bands=False)``."""

    @property
    def origin(self) -> str:
        """``"run"`` (simulated here), ``"reduction"`` or ``"file"`` (read back)."""
        return self._data.origin

    @property
    def verdict(self) -> Optional[Tuple[str, str]]:
        """The reduction's equilibrium verdict (``"equilibrium"``, ``"marginal"``, ``"not in
        equilibrium"``) and the sentence saying which alignment was used and why the verdict
        follows (``verdict_reason`` of ``shpb reduce --summary``); None without a reduction."""
        return self._data.verdict()

    @property
    def warnings(self) -> List[str]:
        """What the user should know about the run (range of validity, reduction windows)."""
        return self._data.warnings()

    @property
    def scene(self) -> str:
        """The scene TOML text the run was made from (a reduction: its command line)."""
        return self._data.scene()

    @property
    def provenance(self) -> Optional[Dict[str, Any]]:
        """What the run read (``/provenance``): scene file, fidelity override, command line and
        the text of every input; ``None`` for a reduction."""
        p = self._data.provenance()
        if p is None:
            return None
        scene_file, fidelity, command_line, inputs = p
        return {
            "scene_file": scene_file,
            "fidelity_override": fidelity,
            "command_line": command_line,
            "inputs": dict(inputs),
        }

    def keys(self) -> List[str]:
        """Every numeric dataset path of the run file, sorted."""
        return list(self._info)

    def __iter__(self) -> Iterator[str]:
        return iter(self._info)

    def __contains__(self, path: object) -> bool:
        return isinstance(path, str) and path.lstrip("/") in self._info

    def __len__(self) -> int:
        return len(self._info)

    def __getitem__(self, path: str) -> np.ndarray:
        """The dataset ``path`` as a new numpy float64 array (0-d for a summary value)."""
        key = path.lstrip("/")
        if key not in self._info:
            raise KeyError(path)
        shape, _ = self._info[key]
        return self._data.array(key).reshape(shape)

    def save(self, path: PathLike, force: bool = False) -> None:
        """Writes the run file ``shpb run -o PATH`` writes (with ``/provenance``), or for a
        reduction the file of ``shpb reduce -o PATH``; a run read by :func:`load` is copied.
        An existing file is refused unless ``force``; the path is checked as the command line
        checks an output (never an input, even with ``force``; ``-`` is not standard output
        here), and the file is written under a temporary name, then moved into place."""
        self._data.save(os.fspath(path), force)

    def plot(self, path: Optional[PathLike] = None, force: bool = False):
        """The figure of ``shpb run --plot``, drawn with matplotlib: force–displacement, and for
        bar tests the gauge signals and the reduced forces. Returns the matplotlib figure. With
        ``path`` the figure is saved there as the command line writes an output: an existing
        file is refused (``FileExistsError``) unless ``force``, before anything is drawn, and the
        file is written under a temporary name, then moved into place."""
        if path is not None:
            path = os.fspath(path)
            if os.path.isdir(path):
                raise IsADirectoryError(errno.EISDIR, f"{path}: a directory, not a file", path)
            if os.path.lexists(path) and not force:
                raise FileExistsError(
                    errno.EEXIST, f"{path}: output file exists; pass force=True to overwrite it", path
                )
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Run.plot needs matplotlib: pip install matplotlib") from e
        panels = []
        if "contact/force" in self:
            panels.append("contact")
        if "time" in self and any(k.startswith("gauges/") for k in self):
            panels.append("gauges")
        if "reduction/force_back" in self:
            panels.append("reduction")
        fig, axes = plt.subplots(1, max(1, len(panels)), figsize=(5 * max(1, len(panels)), 4))
        axes = np.atleast_1d(axes)
        for ax, panel in zip(axes, panels):
            if panel == "contact":
                ax.plot(self["contact/displacement"] * 1e6, self["contact/force"] * 1e-3)
                ax.set_xlabel("approach δ (µm)")
                ax.set_ylabel("contact force (kN)")
            elif panel == "gauges":
                t = self["time"] * 1e6
                for k in self:
                    if k.startswith("gauges/") and k.endswith("/strain"):
                        ax.plot(t, self[k], label=k.split("/")[1])
                ax.set_xlabel("time (µs)")
                ax.set_ylabel("strain")
                ax.legend()
            else:
                t = self["reduction/time"] * 1e6
                ax.plot(t, self["reduction/force_front"] * 1e-3, label="front")
                ax.plot(t, self["reduction/force_back"] * 1e-3, label="back")
                ax.set_xlabel("time (µs)")
                ax.set_ylabel("reduced force (kN)")
                ax.legend()
        fig.tight_layout()
        if path is not None:
            import tempfile

            folder = os.path.dirname(os.path.abspath(path))
            fmt = os.path.splitext(path)[1][1:] or "png"
            fd, tmp = tempfile.mkstemp(prefix=".shpb-tmp-", suffix="." + fmt, dir=folder)
            os.close(fd)
            try:
                fig.savefig(tmp, format=fmt)
                os.replace(tmp, path)
            except BaseException:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
                raise
        return fig

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>{html.escape(k)}</td><td style='text-align:right'>{v:.6g}</td>"
            f"<td>{html.escape(self.units.get(k, ''))}</td></tr>"
            for k, v in self.summary.items()
        )
        warnings = "".join(f"<li>{html.escape(w)}</li>" for w in self.warnings)
        return (
            f"<b>shpb.Run</b> ({html.escape(self.origin)}, {len(self)} datasets)"
            f"<table><tr><th>quantity</th><th>value</th><th>units</th></tr>{rows}</table>"
            + (f"<ul>{warnings}</ul>" if warnings else "")
        )

    def __repr__(self) -> str:
        return f"<shpb.Run {self.origin}: {len(self.summary)} summary values, {len(self)} datasets>"


class Table:
    """The summary table of a sweep: ``table[name]`` is a numpy array with one value per run
    (``peak_force``, ``displacement_at_peak``, ``peak_strain_rate``,
    ``equilibrium_ratio_at_peak``, ``time_to_equilibrium``; ``peak_contact_force`` and
    ``displacement_at_peak_contact_force``, the names of a run's summary, are accepted too);
    :attr:`inputs` holds each swept key's
    values in SI units (or as written, for names), :attr:`labels` the values as written,
    :attr:`warnings` each run's warnings (as ``shpb run`` prints them)."""

    def __init__(self, raw: Tuple[Any, Any, Any, Any, Any]) -> None:
        keys, labels, inputs, columns, warnings = raw
        self.warnings: List[List[str]] = [list(w) for w in warnings]
        """Each run's warnings (a gun pressure outside its calibration, …), in row order."""
        self.keys_swept: List[str] = list(keys)
        self.labels: Dict[str, List[str]] = {
            k: [row[i] for row in labels] for i, k in enumerate(keys)
        }
        self.inputs: Dict[str, np.ndarray] = {}
        self.units: Dict[str, str] = {}
        for k, col in zip(keys, inputs):
            if col is None:
                self.inputs[k] = np.array(self.labels[k], dtype=object)
            else:
                unit, values = col
                self.inputs[k] = np.asarray(values, dtype=np.float64)
                self.units[k] = unit
        self.columns: Dict[str, np.ndarray] = {}
        for name, unit, values in columns:
            self.columns[name] = np.asarray(values, dtype=np.float64)
            self.units[name] = unit

    #: The names of `Run.summary` that a sweep column holds (``table["peak_contact_force"]``).
    ALIASES: Dict[str, str] = {
        "peak_contact_force": "peak_force",
        "displacement_at_peak_contact_force": "displacement_at_peak",
    }

    def __getitem__(self, name: str) -> np.ndarray:
        name = self.ALIASES.get(name, name)
        if name in self.columns:
            return self.columns[name]
        return self.inputs[name]

    def keys(self) -> List[str]:
        """The summary columns."""
        return list(self.columns)

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def _repr_html_(self) -> str:
        head = "".join(
            f"<th>{html.escape(k)} ({html.escape(self.units.get(k, ''))})</th>"
            for k in [*self.keys_swept, *self.columns]
        )
        body = ""
        for i in range(len(self)):
            cells = [html.escape(self.labels[k][i]) for k in self.keys_swept]
            cells += [f"{self.columns[c][i]:.6g}" for c in self.columns]
            body += "<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>"
        return f"<table><tr>{head}</tr>{body}</table>"

    def __repr__(self) -> str:
        return f"<shpb.Table: {len(self)} runs over {', '.join(self.keys_swept)}>"


@contextlib.contextmanager
def _missing_file_is_os_error(*paths: Optional[str]) -> Iterator[None]:
    """A missing input file is a ``FileNotFoundError`` and a directory given for one an
    ``IsADirectoryError`` (both ``OSError``), as :func:`run` raises them for a scene (README,
    Python), with the command line's message: the library reports them as bad input (exit 2)."""
    try:
        yield
    except InputError as e:
        for path in paths:
            if path is None:
                continue
            if os.path.isdir(path):
                raise IsADirectoryError(errno.EISDIR, str(e)) from e
            if not os.path.exists(path):
                raise FileNotFoundError(errno.ENOENT, str(e)) from e
        raise


def _whole(name: str, value: Any, allowed: str) -> int:
    """``value`` as a whole number for the argument ``name``, or an :class:`InputError` naming
    it and ``allowed``: ``int()`` would truncate 2.5 to 2 without a word, and a negative or huge
    number would fail in the binding with an ``OverflowError`` that names no argument."""
    try:
        whole = int(value)
        exact = not isinstance(value, bool) and whole == value
    except (TypeError, ValueError, OverflowError):
        exact = False
    if not exact:
        raise InputError(f"python: `{name}`: {value!r} is not a whole number; allowed: {allowed}")
    if not -(2**63) <= whole < 2**64:
        raise InputError(f"python: `{name}`: {whole} is out of range; allowed: {allowed}")
    if whole < 0:
        raise InputError(f"python: `{name}`: {whole} is negative; allowed: {allowed}")
    return whole


def _number(name: str, value: Any, allowed: str) -> float:
    """``value`` as a float for the argument ``name``, or an :class:`InputError` naming it (the
    range itself is checked by the library, with the command line's message)."""
    try:
        return float(value)
    except (TypeError, ValueError) as e:
        raise InputError(f"python: `{name}`: {value!r} is not a number; allowed: {allowed}") from e


def _mapping(name: str, value: Any) -> Dict[str, Any]:
    """``value`` as a dict of scene keys, or a ``TypeError`` naming the argument."""
    if not isinstance(value, Mapping):
        raise TypeError(
            f"{name}: expected a mapping of scene keys to values (e.g. {{'pressure': '12psi'}}), "
            f"not {type(value).__name__}"
        )
    return dict(value)


def _call(name: str, *args: Any, **kwargs: Any) -> str:
    parts = [repr(a) for a in args] + [f"{k}={v!r}" for k, v in kwargs.items() if v is not None]
    return f"python: shpb.{name}({', '.join(parts)})"


def run(
    scene: Union[PathLike, Mapping[str, Any]],
    fidelity: Optional[str] = None,
    set: Optional[Mapping[str, Any]] = None,
    bands: bool = True,
) -> Run:
    """Runs a virtual test as ``shpb run`` does and returns its :class:`Run`.

    ``scene``: a scene ``.toml`` file, a run file (``.h5``) to run again from its stored inputs,
    or a dict with the keys of a scene file (relative paths in it are relative to the working
    directory). ``fidelity``: ``"fast"``, ``"standard"`` or ``"reference"`` (wins over the
    scene's). ``set``: scene keys to replace, e.g. ``{"pressure": "12psi"}`` (a string is read
    with its units as ``shpb sweep --set`` reads it; dotted keys reach into tables).
    ``bands``: the 90 % bands of a set-up with an ``[uncertainty]`` table (:attr:`Run.bands`;
    ``False`` is ``shpb run --no-bands``). The GIL is released while the test runs.
    """
    if not isinstance(scene, Mapping):
        scene = os.fspath(scene)
    else:
        scene = dict(scene)
    line = _call(
        "run",
        scene if isinstance(scene, str) else "<dict>",
        fidelity=fidelity,
        set=set,
        **({} if bands else {"no_bands": True}),
    )
    overrides = _mapping("set", set) if set is not None else None
    return Run(_shpb.run(scene, fidelity, overrides or None, line, bands))


def load(path: PathLike) -> Run:
    """Reads a run file written by ``shpb run -o`` or :meth:`Run.save` (or a reduction file of
    ``shpb reduce -o``)."""
    path = os.fspath(path)
    if os.path.isdir(path):
        raise IsADirectoryError(errno.EISDIR, f"{path}: {os.strerror(errno.EISDIR)}")
    if not os.path.exists(path):
        raise FileNotFoundError(errno.ENOENT, f"{path}: {os.strerror(errno.ENOENT)}")
    return Run(_shpb.load(path))


def gun(pressure: Union[str, float], bars: PathLike = "authors") -> float:
    """The striker velocity (m/s) the gas gun of the set-up ``bars`` (a built-in set-up or a
    set-up file) gives at ``pressure`` (text with units, e.g. ``"10psi"``, or a float in Pa)."""
    if not isinstance(pressure, str):
        pressure = f"{float(pressure)!r}Pa"
    return _shpb.gun(pressure, os.fspath(bars))


def curve(
    pair: str = "ss440c",
    rate: float = 0.0,
    to: float = 250e-6,
    points: int = 101,
    law: str = "burgoyne-daraio",
) -> Tuple[np.ndarray, np.ndarray]:
    """The loading curve F(δ) of a specimen (``shpb curve``): ``(displacement_m, force_N)`` on
    ``points`` approaches from 0 to ``to`` (m) at the global strain rate ``rate`` (1/s)."""
    return _shpb.curve(
        pair,
        _number("rate", rate, "0 to 1e9 1/s"),
        _number("to", to, "greater than 0, in m"),
        _whole("points", points, "2 to 10000000"),
        law,
    )


def reduce(
    record: PathLike,
    bars: Optional[PathLike] = None,
    dispersion: Union[str, bool] = "bancroft",
    tyas_pope: bool = False,
    align: str = "geometric",
    smooth: Optional[float] = None,
    specimen_length_m: Optional[float] = None,
    specimen_diameter_m: Optional[float] = None,
    layout: Optional[PathLike] = None,
    balance_bound_s: float = 60e-6,
    specimen: Optional[PathLike] = None,
    tension: bool = False,
    wave_separation: str = "none",
    filter: Optional[str] = None,
    filter_cutoff: Optional[float] = None,
    filter_order: Optional[int] = None,
    filter_window: Optional[float] = None,
    baseline: str = "start-mean",
) -> Run:
    """The lab's reduction (``shpb reduce``) of a raw record (CSV: time_s, incident_V,
    transmission_V) or of a run file, as a :class:`Run` with ``reduction/*`` datasets.
    ``bars``: the set-up (default: the run file's own, else ``"authors"``). ``dispersion``:
    ``"none"``, ``"bancroft"`` or ``"pochhammer-chree"`` (``--dispersion``; ``True``/``False``,
    the old form, mean ``"bancroft"``/``"none"``); ``tyas_pope``: the Tyas–Pope amplitude
    factors (``--tyas-pope``). ``align``: ``"geometric"``, ``"foot"`` or ``"balance"``
    (``--align``); ``smooth``: moving-average width, s (``--smooth``; without ``filter``, the
    moving-average filter of that width, 0 is no filter). ``filter``: ``"none"``,
    ``"butterworth"`` (the default: 4th order forward and backward at the bars' dispersion
    band), ``"savitzky-golay"`` or ``"moving-average"`` (``--filter``), with ``filter_cutoff``
    (Hz), ``filter_order`` and ``filter_window`` (s) (``--filter-cutoff``, ``--filter-order``,
    ``--filter-window``; docs/physics.md §7.12). ``baseline``: ``"start-mean"`` or
    ``"linear-drift"`` (``--baseline``). ``specimen_length_m`` and
    ``specimen_diameter_m`` (both or neither): a cylindrical specimen's 1/2/3-wave curves,
    ``reduction/cylinder/{one_wave,two_wave,three_wave}/
    {stress,strain,strain_rate,true_stress,true_strain}``, compression positive
    (docs/physics.md §7.8), and ``peak_stress``, ``strain_at_peak_stress``,
    ``mean_strain_rate`` in the summary. ``layout``: a record layout file (``--layout``) for a
    lab's own text export. ``balance_bound_s``: the bound of ``align="balance"``'s search on
    each window shift, s (``--balance-bound``). ``specimen``: a specimen file (``--specimen``),
    a ``[specimen]`` table as in a scene: spheres of any diameter (the strain rate over their
    radii, δ̇/Σrᵢ) or ``shape = "cylinder"`` (its 1/2/3-wave curves); not with
    ``specimen_length_m``/``specimen_diameter_m``; for a run file it overrides the run's own.
    ``tension``: a tension test (``--tension``, docs/physics.md §7.8.1): forces, stresses and
    strains tension positive, a cylinder specimen needed (a run file of a tension scene is
    reduced in tension without it).

    ``wave_separation``: ``"none"``, ``"one-gauge"`` or ``"two-gauge"``
    (``--wave-separation``, docs/physics.md §7.11): the waves toward and away from the specimen
    at each face when the pulses overlap at the gauges (two gauges: the set-up's
    ``incident_2`` and ``transmission_2`` channels, recorded in a run file)."""
    if isinstance(dispersion, bool):
        dispersion = "bancroft" if dispersion else "none"
    return Run(
        _shpb.reduce(
            os.fspath(record),
            None if bars is None else os.fspath(bars),
            dispersion,
            bool(tyas_pope),
            align,
            None
            if smooth is None
            else _number("smooth", smooth, "0 (off) or a positive width in seconds"),
            specimen_length_m,
            specimen_diameter_m,
            None if layout is None else os.fspath(layout),
            _number("balance_bound_s", balance_bound_s, "a positive bound in seconds"),
            None if specimen is None else os.fspath(specimen),
            bool(tension),
            wave_separation,
            filter,
            None
            if filter_cutoff is None
            else _number("filter_cutoff", filter_cutoff, "a positive cut-off in Hz"),
            filter_order,
            None
            if filter_window is None
            else _number("filter_window", filter_window, "a positive window in seconds"),
            baseline,
        )
    )


def _label(v: Any, key: str = "") -> str:
    if v is None or not isinstance(v, (str, bool, int, float, np.integer, np.floating)):
        raise InputError(
            f"python: `{key}`: a value of type {type(v).__name__} cannot be swept; allowed: "
            "str, int, float or bool values, e.g. ['8psi', '10psi'] or [0.5e-3, 1e-3]"
        )
    if isinstance(v, str):
        return v
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    return repr(float(v))


def _scene_missing_is_os_error(fn: Any) -> Any:
    """:func:`_missing_file_is_os_error` for the ``scene`` (first argument) of ``fn``."""

    @functools.wraps(fn)
    def wrapper(scene: PathLike, *args: Any, **kwargs: Any) -> Any:
        with _missing_file_is_os_error(os.path.abspath(os.fspath(scene))):
            return fn(scene, *args, **kwargs)

    return wrapper


@_scene_missing_is_os_error
def sweep(
    scene: PathLike,
    set: Mapping[str, Union[Sequence[Any], str]],
    jobs: int = 1,
    client: Any = None,
    shards: Optional[int] = None,
    fidelity: Optional[str] = None,
) -> Table:
    """Runs ``scene`` over the Cartesian product of the values in ``set`` (``shpb sweep``),
    on ``jobs`` threads (the GIL is released), and returns the summary :class:`Table`.

    ``set``: scene key → list of values (``{"pressure": ["8psi", "10psi"]}``), or the text of
    ``shpb sweep --set`` (``{"pressure": "5psi:20psi:16"}``).

    ``client``: a ``dask.distributed.Client`` (a ``LocalCluster``, a SLURM cluster of
    dask-jobqueue, Kubernetes, ...). The sweep is then cut into ``shards`` shards (default: four
    per worker requested, or one per 16 runs if more, fixed before any worker registers:
    :func:`_plan_shards`), exactly as ``shpb sweep --shard k/n`` cuts it, each shard runs on a
    worker (``jobs`` threads there) and the rows are put back in sweep order: the table is the one
    ``shpb sweep`` gives. Workers must see the scene and the files it names at the same path
    (a shared file system).

    ``fidelity``: the preset of every run (``shpb sweep --fidelity``), the same as
    ``set={"fidelity": [fidelity]}``; a key given both ways is refused.
    """
    specs = []
    axes = _mapping("set", set)
    if not axes:
        raise InputError(
            "python: `set`: no key to sweep; allowed: scene keys with their values, "
            "e.g. {'pressure': ['8psi', '10psi']} (shpb sweep --set)"
        )
    jobs = _whole("jobs", jobs, "a number of worker threads (0 counts as 1)")
    if shards is not None and _whole("shards", shards, "a whole number ≥ 1") < 1:
        raise InputError(f"python: `shards`: {shards}; allowed: a whole number ≥ 1")
    for key, values in axes.items():
        if isinstance(values, str):
            specs.append(f"{key}={values}")
        elif isinstance(values, (bool, int, float, np.integer, np.floating)) or values is None:
            specs.append(f"{key}={_label(values, key)}")
        else:
            specs.append(f"{key}={','.join(_label(v, key) for v in values)}")
    if fidelity is not None:
        # `--fidelity NAME` is the one-value axis `--set fidelity=NAME`, after the others.
        specs.append(f"fidelity={fidelity}")
    path = os.path.abspath(os.fspath(scene))
    if client is None:
        keys, rows = _interruptible(_sweep_shard, path, specs, int(jobs), 1, 1)
    else:
        try:
            parts = _on_cluster(
                client, _sweep_shard, shards, path, specs, int(jobs), points=_sweep_points(specs)
            )
        except KeyboardInterrupt as e:
            done = getattr(e, "parts", [])
            if done:
                rows = [r for _, part in done for r in part]
                e.table = Table(_shpb.sweep_table(done[0][0], rows, True))
                e.finished = len(rows)
            raise
        keys = parts[0][0]
        rows = [r for _, part in parts for r in part]
    return Table(_shpb.sweep_table(keys, rows))


class Study:
    """An uncertainty study (:func:`study`, ``shpb study``): :attr:`runs` is the :class:`Table` of
    its runs (one row per sample: the inputs drawn and the summary), :attr:`stats` the statistics
    of each input and summary quantity, as ``shpb study --summary`` writes them::

        s.stats["peak_force"]["mean"], s.stats["peak_force"]["p95"], s.stats["peak_force"]["S"]["pressure"]
    """

    def __init__(self, raw: Tuple[Any, Any, Any]) -> None:
        table, stats, spec = raw
        self.runs: Table = Table(table)
        """One row per sample: ``runs["peak_force"]``, ``runs.inputs["pressure"]`` (SI units)."""
        keys = self.runs.keys_swept
        self.stats: Dict[str, Dict[str, Any]] = {}
        """Quantity (a summary column, or ``"input KEY"``) → ``unit``, ``n``, ``mean``, ``sd``,
        ``p5``, ``p50``, ``p95`` and ``S`` (first-order sensitivity index to each input; empty for
        an input's own row)."""
        for name, unit, n, mean, sd, (p5, p50, p95), first in stats:
            self.stats[name] = {
                "unit": unit,
                "n": n,
                "mean": mean,
                "sd": sd,
                "p5": p5,
                "p50": p50,
                "p95": p95,
                "S": dict(zip(keys, first)),
            }
        self.inputs: List[str] = list(spec)
        """The study's description: the samples and the seed, the fidelity preset if given, each
        input's distribution."""

    def __repr__(self) -> str:
        return f"<shpb.Study: {len(self.runs)} samples of {', '.join(self.runs.keys_swept) or 'no input'}>"


@_scene_missing_is_os_error
def study(
    scene: PathLike,
    samples: int = 32,
    seed: int = 1,
    jobs: int = 1,
    gun_scatter: bool = True,
    client: Any = None,
    shards: Optional[int] = None,
    fidelity: Optional[str] = None,
) -> Study:
    """Propagates the scene's uncertainties (``shpb study SCENE --samples N --seed S``): its
    distributions (``pressure = { mean = "12.5psi", sd = "0.6psi" }``) and, with ``gun_scatter``,
    the set-up's shot-to-shot gun scatter are drawn by a seeded Latin hypercube, each sample is
    run, and the :class:`Study` holds the runs and their statistics.

    ``client``: a ``dask.distributed.Client``; the samples are then run in ``shards`` shards
    (default as for :func:`sweep`, :func:`_plan_shards`; every n-th sample as ``--shard k/n``
    cuts a sweep), and the study is the one ``shpb study`` gives, bit for bit. Workers must see
    the scene at the same path.

    ``fidelity``: ``"fast"``, ``"standard"`` or ``"reference"`` for every run, in place of the
    scene's (``shpb study --fidelity``).
    """
    samples = _whole("samples", samples, "2 to 1000000 samples")
    seed = _whole("seed", seed, "a whole number from 0 to 18446744073709551615")
    jobs = _whole("jobs", jobs, "a number of worker threads (0 counts as 1)")
    if shards is not None and _whole("shards", shards, "a whole number ≥ 1") < 1:
        raise InputError(f"python: `shards`: {shards}; allowed: a whole number ≥ 1")
    path = os.path.abspath(os.fspath(scene))
    args = (path, int(samples), int(seed), int(jobs), bool(gun_scatter), fidelity)
    if client is None:
        rows = _interruptible(_study_shard, *args, 1, 1)
    else:
        try:
            parts = _on_cluster(client, _study_shard, shards, *args, points=int(samples))
        except KeyboardInterrupt as e:
            e.finished = sum(len(p) for p in getattr(e, "parts", []))
            raise
        rows = [r for part in parts for r in part]
    return Study(
        _shpb.study_table(path, int(samples), int(seed), bool(gun_scatter), rows, fidelity)
    )


def _interruptible(fn: Any, *args: Any) -> Any:
    """Calls ``fn(*args)``; on Ctrl-C (KeyboardInterrupt, seen within 20 ms while runs go on)
    the exception is raised again with the runs finished before it as ``e.table``, a
    :class:`Table` of those rows (in sweep order), and their count as ``e.finished``."""
    try:
        return fn(*args)
    except KeyboardInterrupt as e:
        raw = getattr(e, "table", None)
        if isinstance(raw, tuple):
            e.table = Table(raw)
        raise


def _study_shard(
    scene: str,
    samples: int,
    seed: int,
    jobs: int,
    gun_scatter: bool,
    fidelity: Optional[str],
    k: int,
    n: int,
) -> List[Any]:
    """Shard ``k`` of ``n`` of a study, run where a Dask worker calls it."""
    return _shpb.study_runs(scene, samples, seed, jobs, gun_scatter, (k, n), fidelity)


def _sweep_shard(
    scene: str, specs: List[str], jobs: int, k: int, n: int
) -> Tuple[Any, ...]:
    """Shard ``k`` of ``n`` of a sweep, run where a Dask worker calls it."""
    return _shpb.sweep_runs(scene, specs, jobs, (k, n))


#: Runs a shard holds at most by default once the points outnumber four shards a worker
#: (:func:`_plan_shards`).
SHARD_CHUNK = 16


def _plan_shards(points: int, workers: int, chunk: int = SHARD_CHUNK) -> int:
    """The default number of shards of ``points`` runs on a cluster of ``workers`` workers
    requested (issue 45): max(4 × workers, ⌈points / chunk⌉), at most one shard a run and at
    least one shard. It is fixed by the points and the workers asked for, not by the workers
    registered when the shards are submitted: a cluster still starting (its workers queued in
    SLURM, say) gets every worker busy as they arrive, where one shard per registered worker
    gave a sweep submitted before them one shard on one worker. Four shards a worker balance
    runs of unequal cost; any number gives the same table (the rows are put back in sweep
    order)."""
    points, workers, chunk = int(points), max(int(workers), 1), max(int(chunk), 1)
    if points < 1:
        return 1
    return max(1, min(max(4 * workers, -(-points // chunk)), points))


def _workers_requested(client: Any) -> int:
    """The workers asked of ``client``'s cluster, started or not: the most of its ``plan`` (the
    workers asked for, ``SpecCluster.plan``: ``LocalCluster``, dask-jobqueue, dask-kubernetes),
    its ``requested`` (those launched) and the workers registered now (all a client of a
    scheduler alone knows); at least 1."""
    cluster = getattr(client, "cluster", None)
    counts = [0]
    for name in ("plan", "requested"):
        try:
            counts.append(len(getattr(cluster, name)))
        except Exception:  # noqa: BLE001 (no such attribute, or not a collection)
            pass
    try:
        counts.append(len(client.scheduler_info().get("workers", {})))
    except Exception:  # noqa: BLE001 (a scheduler that does not answer: counted as none)
        pass
    return max(1, *counts)


def _sweep_points(specs: Sequence[str]) -> int:
    """The runs of a sweep of ``--set`` texts, counted as ``shpb sweep`` expands them
    (``KEY=START:STOP:COUNT`` has COUNT values, ``KEY=V1,V2,…`` one per comma); a text it
    would refuse counts 1 (the shard then reports the error)."""
    total = 1
    for spec in specs:
        values = spec.split("=", 1)[1] if "=" in spec else ""
        if ":" in values:
            try:
                count = int(values.split(":")[-1].strip())
            except ValueError:
                count = 1
        else:
            count = len(values.split(","))
        total *= max(count, 1)
    return total


def _on_cluster(
    client: Any, fn: Any, shards: Optional[int], *args: Any, points: int = 1
) -> List[Any]:
    """Runs ``fn(*args, k, n)`` for the shards k = 1..n on a Dask ``client`` and gathers the
    results (in shard order); ``n`` is ``shards`` or :func:`_plan_shards` of the ``points`` and
    the workers requested (:func:`_workers_requested`)."""
    if shards is None:
        shards = _plan_shards(points, _workers_requested(client))
    n = int(shards)
    if n < 1:
        raise InputError(f"shards: {shards} (allowed: a whole number ≥ 1)")
    futures = [client.submit(fn, *args, k, n, pure=False) for k in range(1, n + 1)]
    try:
        # Polled, not a blocking gather: Ctrl-C is seen within 20 ms, not when a shard ends.
        while not all(f.done() for f in futures):
            time.sleep(0.02)
    except KeyboardInterrupt as e:
        # The shards not finished are cancelled (a shard already running on a worker runs to
        # its end there: Dask cannot stop a running task); the finished ones are kept, in
        # shard order, as ``e.parts``.
        client.cancel([f for f in futures if not f.done()])
        e.parts = [f.result() for f in futures if f.done() and f.status == "finished"]
        raise
    return list(client.gather(futures))


class Fit:
    """What :func:`fit` found (``shpb fit``; docs/physics.md §12): each free key's best fit and
    posterior, the sampler's chain and each record with the model and its predictive band::

        f = shpb.fit("scenes/force-driven-ss440c-10psi.toml",
                     {"specimen.yield_stress_pa": ("1.2GPa", "2.6GPa"), "specimen.jc_c": (0, 0.1)})
        f.parameters["specimen.yield_stress_pa"]["value"]     # Pa, the least-squares best fit
        f.parameters["specimen.yield_stress_pa"]["band_90"]   # [5 %, 95 %] posterior quantiles
        f.samples                                             # numpy [n, keys], after burn-in
    """

    def __init__(self, data: "_shpb.FitData") -> None:
        self._data = data
        self._json: Dict[str, Any] = json.loads(data.json())
        self.keys: List[str] = list(data.keys())
        """The free keys, in the order of the last axis of :attr:`samples` and :attr:`chain`."""
        self.parameters: Dict[str, Dict[str, Any]] = {
            k: self._json["parameters"][k] for k in self.keys
        }
        """Key → ``value`` (least-squares best fit), ``unit``, ``band_90`` ``[low, high]``
        (5 % and 95 % posterior quantiles), ``median``, ``min``, ``max`` (the bounds),
        ``prior_normal`` (``[mean, sd]`` or None), ``tau_steps`` (integrated autocorrelation
        time) and ``ess`` (effective sample size): the ``parameters`` of ``shpb fit --json``
        (None for a number that is not finite)."""
        steps, walkers, p = data.shape()
        self.chain: np.ndarray = data.chain().reshape(steps, walkers, p)
        """Every walker's position at every step, ``[steps, walkers, keys]`` (SI units)."""
        self.log_prob: np.ndarray = data.log_prob().reshape(steps, walkers)
        """The log posterior of each position of :attr:`chain`, ``[steps, walkers]``."""
        self.samples: np.ndarray = data.samples().reshape(-1, p)
        """The chain after the burn-in, ``[(steps − burn_in) × walkers, keys]``, step by step."""
        self.burn_in: int = data.burn_in
        """Steps of :attr:`chain` dropped as burn-in."""
        self.correlations: np.ndarray = np.asarray(data.correlations(), dtype=np.float64).reshape(p, p)
        """The posterior Pearson correlations ``[keys, keys]`` (after the burn-in)."""
        self.records: List[Dict[str, Any]] = list(data.records())
        """Each record fitted: ``name``, ``x_label``, ``x_unit``, ``y_label``, ``y_unit``, numpy
        ``x``, ``y`` (the record), ``best`` (the model at the best fit), ``band_low``,
        ``band_high`` (the 90 % posterior-predictive band, empty when none), ``noise_sd`` (y
        units), ``noise_correlation`` (points) and ``inside_band`` (fraction of points)."""
        self.warnings: List[str] = list(data.warnings())
        """What the fit warned about (as ``shpb fit`` prints them): a chain shorter than 10
        autocorrelation times, an interrupted sampler, …"""

    def to_json(self) -> Dict[str, Any]:
        """The object ``shpb fit --json`` prints (a new dict each call)."""
        return json.loads(self._data.json())

    def save(self, path: PathLike, force: bool = False) -> None:
        """Writes the fit file of ``shpb fit -o PATH`` (HDF5); an existing file is refused unless
        ``force``, the scene and records never overwritten."""
        self._data.save(os.fspath(path), bool(force))

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>{html.escape(k)}</td><td>{_g(p['value'])}</td><td>{_g(p['median'])}</td>"
            f"<td>{_g(p['band_90'][0])} – {_g(p['band_90'][1])}</td>"
            f"<td>{html.escape(p['unit'])}</td><td>{_g(p['ess'])}</td></tr>"
            for k, p in self.parameters.items()
        )
        warnings = "".join(f"<li>{html.escape(w)}</li>" for w in self.warnings)
        return (
            f"<b>shpb.Fit</b> ({self._json['walkers']} walkers × {self._json['steps']} steps)"
            "<table><tr><th>key</th><th>best</th><th>median</th><th>90 % interval</th>"
            f"<th>unit</th><th>ESS</th></tr>{rows}</table>"
            + (f"<ul>{warnings}</ul>" if warnings else "")
        )

    def __repr__(self) -> str:
        return (
            f"<shpb.Fit of {', '.join(self.keys)}: {self._json['walkers']} walkers × "
            f"{self._json['steps']} steps>"
        )


def _g(v: Any) -> str:
    return "–" if v is None else f"{v:.6g}"


def _bound(key: str, v: Any) -> str:
    """One bound of a free key as ``--free`` reads it: text with units as written, a number in
    SI units (its shortest exact form)."""
    if isinstance(v, str):
        return v.strip()
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise InputError(
            f"python: `free {key}`: {v!r} is not a bound; allowed: a number in SI units or text "
            "with units, e.g. (1.2e9, 2.6e9) or ('8psi', '12psi')"
        )
    return repr(float(v))


def _free_specs(free: Any) -> List[str]:
    """``free`` as ``--free KEY=MIN:MAX`` texts: a dict {key: (min, max)}, a list of texts, or
    one text."""
    allowed = (
        "{KEY: (MIN, MAX)} or ['KEY=MIN:MAX', …], e.g. {'specimen.yield_stress_pa': (1.2e9, 2.6e9)}"
    )
    if isinstance(free, str):
        return [free]
    if isinstance(free, Mapping):
        specs = []
        for key, bounds in free.items():
            if not isinstance(key, str):
                raise InputError(f"python: `free`: key {key!r} is not a string; allowed: {allowed}")
            if isinstance(bounds, (str, bytes)) or not isinstance(bounds, Sequence) or len(bounds) != 2:
                raise InputError(
                    f"python: `free {key}`: {bounds!r} is not a (MIN, MAX) pair; allowed: {allowed}"
                )
            specs.append(f"{key}={_bound(key, bounds[0])}:{_bound(key, bounds[1])}")
        return specs
    if isinstance(free, Sequence) and all(isinstance(f, str) for f in free):
        return list(free)
    raise InputError(f"python: `free`: {free!r}; allowed: {allowed}")


def _prior_specs(prior: Any) -> List[str]:
    """``prior`` as ``--prior KEY=normal:MEAN:SD`` texts: a dict {key: ("normal", mean, sd)} (or
    {key: "normal:MEAN:SD"}), a list of texts, or one text."""
    allowed = "{KEY: ('normal', MEAN, SD)} or ['KEY=normal:MEAN:SD', …] (SI units, SD > 0)"
    if prior is None:
        return []
    if isinstance(prior, str):
        return [prior]
    if isinstance(prior, Mapping):
        specs = []
        for key, p in prior.items():
            if isinstance(p, str):
                specs.append(f"{key}={p}")
                continue
            if not isinstance(p, Sequence) or len(p) != 3:
                raise InputError(
                    f"python: `prior {key}`: {p!r} is not ('normal', MEAN, SD); allowed: {allowed}"
                )
            kind, mean, sd = p
            parts = [str(kind)] + [
                repr(_number(f"prior {key}", x, allowed)) if not isinstance(x, str) else x
                for x in (mean, sd)
            ]
            specs.append(f"{key}={':'.join(parts)}")
        return specs
    if isinstance(prior, Sequence) and all(isinstance(p, str) for p in prior):
        return list(prior)
    raise InputError(f"python: `prior`: {prior!r}; allowed: {allowed}")


def fit(
    scene: PathLike,
    free: Union[Mapping[str, Tuple[Any, Any]], Sequence[str], str],
    *,
    prior: Union[Mapping[str, Any], Sequence[str], str, None] = None,
    record: Union[PathLike, Sequence[PathLike], None] = None,
    residual: Optional[str] = None,
    walkers: Optional[int] = None,
    steps: int = 200,
    burn_in: Optional[int] = None,
    seed: int = 1,
    jobs: Optional[int] = None,
    output: Optional[PathLike] = None,
    plot: Optional[PathLike] = None,
    corner: Optional[PathLike] = None,
    force: bool = False,
) -> Fit:
    """Fits free scene keys to records as ``shpb fit`` does (docs/physics.md §12): least
    squares, a noise model from the best fit's residuals, then the posterior sampled by an
    affine-invariant ensemble sampler; returns the :class:`Fit`. For the same arguments and
    ``seed`` the result is the command line's, whatever ``jobs``.

    ``scene``: a scene ``.toml`` file (a dict scene is not taken: the fit reruns the file).
    ``free``: ``{KEY: (MIN, MAX)}`` (numbers in SI units, or text with units as ``--free`` takes
    it: ``("8psi", "12psi")``) or a list of ``"KEY=MIN:MAX"`` (``--free``); keys as ``--set``
    names them, and the fit's own ``time_shift_s``. ``prior``: ``{KEY: ("normal", MEAN, SD)}`` or
    a list of ``"KEY=normal:MEAN:SD"`` (``--prior``, SI units). ``record``: a file or a list of
    files (``--record``: raw gauge records or run files reduced through the scene's set-up, or
    reduced curves as CSV); None: the scene's own record. ``residual``: ``"force-time"``,
    ``"force-approach"``, ``"stress-strain"`` or ``"strains"`` (``--residual``; default by the
    scene). ``walkers`` (even, ≥ 2 × keys; default max(16, 4 × keys)), ``steps``, ``burn_in``
    (default a quarter of ``steps``), ``seed``, ``jobs`` (threads; default one per core): the
    sampler's settings. ``output`` (``.h5``), ``plot`` and ``corner`` (``.png``): the files of
    ``-o``, ``--plot``, ``--corner``, checked before the fit and written after it; an existing
    file is refused (:class:`InputError`) unless ``force``.

    Bad input raises :class:`InputError` (a ``ValueError``) naming the key or argument, a
    missing scene or record ``FileNotFoundError``. The GIL is released during the fit. Ctrl-C
    stops the sampler between steps (within one step's runs; the least squares before it runs
    to its end) and raises ``KeyboardInterrupt`` with the fit of the steps done as ``e.fit`` (a
    :class:`Fit` with a warning saying so); no output file is written then.
    """
    if isinstance(scene, Mapping):
        raise TypeError(
            "fit: `scene` must be a scene file path (the fit reruns the file with each value; a "
            "dict scene is not taken)"
        )
    scene = os.fspath(scene)
    specs = _free_specs(free)
    priors = _prior_specs(prior)
    if record is None:
        records: List[str] = []
    elif isinstance(record, (str, os.PathLike)):
        records = [os.fspath(record)]
    else:
        records = [os.fspath(r) for r in record]
    for r in records:
        if os.path.isdir(r):
            raise IsADirectoryError(errno.EISDIR, f"record {r}: a directory, not a file", r)
        if not os.path.exists(r):
            raise FileNotFoundError(errno.ENOENT, f"record {r}: {os.strerror(errno.ENOENT)}", r)
    walkers = 0 if walkers is None else _whole("walkers", walkers, "an even number ≥ 2 × keys")
    steps = _whole("steps", steps, "4 sampler steps or more")
    if burn_in is not None:
        burn_in = _whole("burn_in", burn_in, "fewer burn-in steps than steps")
    seed = _whole("seed", seed, "a whole number from 0 to 18446744073709551615")
    if jobs is not None:
        jobs = _whole("jobs", jobs, "1 up to 4 worker threads per core of the machine")
    paths = [None if p is None else os.fspath(p) for p in (output, plot, corner)]
    line = _call(
        "fit",
        scene,
        free=specs,
        prior=priors or None,
        record=records or None,
        residual=residual,
        walkers=walkers or None,
        steps=steps,
        burn_in=burn_in,
        seed=seed,
        jobs=jobs,
        output=paths[0],
        plot=paths[1],
        corner=paths[2],
        **({"force": True} if force else {}),
    )
    try:
        data = _shpb.fit(
            scene,
            specs,
            priors,
            records,
            residual,
            walkers,
            steps,
            burn_in,
            seed,
            jobs,
            *paths,
            bool(force),
            line,
        )
    except KeyboardInterrupt as e:
        partial = getattr(e, "fit", None)
        if partial is not None and not isinstance(partial, Fit):
            e.fit = Fit(partial)
        raise
    return Fit(data)
