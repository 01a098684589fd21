"""Reading a measured topography: one channel of an instrument file through SurfaceTopography (every
format it reads: x3p, Digital Surf .sur, Sensofar .plu, Wyko .opd, Zygo .dat/.datx, Alicona .al3d,
AFM files, ...; ``formats()``) or a plain height matrix without units (.npy, .txt, .csv, .asc:
``multiscale.micro.surface.read_matrix``, with a pixel size), in SI units, the file's own units and
pixel sizes unless a caller overrides them (noted in the result). Undefined points (no value from
the instrument; NaN in a matrix) are NaN. Conditioning is ``multiscale.micro.topography``'s.
"""
from __future__ import annotations

import logging
import os
import time
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from multiscale.errors import InputError, check_pair, check_positive
from multiscale.micro.spectrum import surface_topography
from multiscale.micro.surface import read_matrix

MATRIX_SUFFIXES = (".npy", ".txt", ".csv", ".asc")    # plain height matrices (no units in the file)
TALLEST = 1e-2            # m: heights beyond are no roughness measurement (an instrument's z range is mm)
WIDEST = 1.0              # m: maps wider are no roughness measurement (a profilometer's stage is 0.1 m)
LOWEST = 1e-10            # m: heights all within it are none either (an atomic step; offsets and noise exceed it)
NARROWEST = 16            # points: a map with fewer along a side is warned of (a strip or line scan, not an areal map)
UNDERFLOW = 1e-60         # m: heights all within it have powers (h^4 in Sku) that underflow: refused
KEPT_BYTES = 2**30        # heights of the measurements kept for the next read (an 8000² map is 0.5 GB)
SETTLED = 2.0             # s: a file modified more recently is not kept (file times are as coarse as a clock tick)
_KEPT: dict = {}          # (file, channel, pixel size, height unit, prefix) -> ((mtime, size), Measurement)


class TopographyWarning(UserWarning):
    """Something the file said was overridden, or an interface covered by copies of a measurement."""


COMMAND_LINE = "--"       # the prefix that names the options as ``multiscale surface`` takes them


def option(prefix: str, key: str, value: str | None = None) -> str:
    """Option ``key`` (a keyword of ``read_topography`` or ``condition``) as messages name it, with
    its ``value`` if given: ``prefix`` + key (a scene's "roughness.height_unit = 1e-09 m"; "" the
    Python keyword) or, ``prefix`` ``COMMAND_LINE``, as ``multiscale surface`` takes it
    ("--height-unit 1e-09 m"; the file: "FILE")."""
    if prefix == COMMAND_LINE:
        name = "FILE" if key == "file" else COMMAND_LINE + key.replace("_", "-")
        return name if value is None else f"{name} {value}"
    return prefix + key if value is None else f"{prefix}{key} = {value}"


def example(prefix: str, key: str, text: str, metres: str) -> str:
    """An example value of option ``key`` as the caller writes it: ``text``, a quantity with its
    unit, in a scene or on the command line; in Python (``prefix`` "") ``key=metres``, a number in
    metres (a user trial passed the message's "0.5 um" to the keyword, which takes metres)."""
    return f"{key}={metres} (metres)" if prefix == "" else text


def formats() -> list[str]:
    """Name (extensions) of every format SurfaceTopography reads."""
    return [f"{r.name()} (.{', .'.join(r.file_extensions())})" for r in surface_topography().IO.readers
            if r.format() not in ("npy", "asc", "xyz")] + [
        "plain height matrices .npy, .txt, .csv, .asc (with a pixel size)"]


# --------------------------------------------------------------------------- reading
@dataclass(frozen=True)
class Measurement:
    """One channel of a measured topography, as read: heights [m] (ny, nx), NaN where undefined;
    pixel sizes [m]; where it came from; ``notes``: what overrode the file (one line each);
    ``found``: its outliers by form removal, once searched (``topography.condition``)."""

    heights: np.ndarray
    dx: float
    dy: float
    path: Path
    channel: int = 0
    channel_name: str = ""
    unit: str | None = None       # the file's length unit (None: none in the file)
    notes: tuple[str, ...] = ()
    found: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def shape(self) -> tuple[int, int]:
        return self.heights.shape

    @property
    def size(self) -> tuple[float, float]:
        """(Lx, Ly) [m]."""
        return self.shape[1] * self.dx, self.shape[0] * self.dy

    @property
    def undefined(self) -> int:
        """Number of undefined points."""
        return int(np.isnan(self.heights).sum())


def _reader(path: Path, name: str):
    ST = surface_topography()
    try:
        with _quiet():
            reader = ST.open_topography(str(path))
    except (ST.Exceptions.UnknownFileFormat, ST.Exceptions.CannotDetectFileFormat):
        said = _format_error(path) or "not a format SurfaceTopography recognises"
        raise InputError(name, path.name, f"cannot read it as a topography: {said} (`multiscale surface --formats` "
                         "lists the formats)") from None
    except Exception as exc:    # any other parser failure on a user's file: one error naming it
        raise InputError(name, path.name, f"cannot read it as a topography ({_first_line(exc)})") from None
    suffix = path.suffix.lower().lstrip(".")
    claimed = tuple(r for r in ST.IO.readers if suffix and suffix in r.file_extensions())
    if claimed and not isinstance(reader, claimed):   # a .x3p cut to 2 n² bytes was "NASA SRTM" (by its size)
        said = _format_error(path) or f"as {', '.join(r.name() for r in claimed)}, it was read without error"
        raise InputError(name, path.name, f"its contents were taken for {reader.name()}, not the format of its "
                         f".{suffix} extension: {said} (a damaged file, or one to rename)")
    return reader


@contextmanager
def _quiet():
    """No logging while SurfaceTopography's readers try a file: on a damaged one some log its bytes
    as errors (igor2's on a truncated .opd: megabytes on the terminal)."""
    before = logging.root.manager.disable
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(before)


def _format_error(path: Path) -> str | None:
    """What the readers of the file's extension say about a file the format detection refused (a
    truncated or damaged file of a known format), or None for an extension no reader claims."""
    suffix = path.suffix.lower().lstrip(".")
    said = []
    for reader in surface_topography().IO.readers:
        if suffix and suffix in reader.file_extensions():
            try:
                with _quiet():
                    reader(str(path))
            except Exception as exc:    # the reader's own words on what is wrong with the file
                said.append(f"as {reader.name()}, {_first_line(exc)}")
    return "; ".join(said) or None


def _first_line(exc: Exception) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0][:160] if text else ''}"


def _channel(reader, path: Path, channel, prefix: str):
    channels = reader.channels
    listing = ", ".join(f"{c.index} \"{c.name}\" ({c.dim}-D)" for c in channels)
    if channel is None:
        ch = reader.default_channel
    elif not isinstance(channel, (int, np.integer)) or not 0 <= channel < len(channels):
        raise InputError(option(prefix, "channel"), channel, f"{path.name} has the channels {listing}")
    else:
        ch = channels[int(channel)]
    if ch.dim != 2:
        raise InputError(option(prefix, "file"), path.name, f"channel {ch.index} (\"{ch.name}\") is a {ch.dim}-D "
                         f"profile (line scan): a height map (2-D) is needed; channels: {listing}")
    return ch


def read_topography(path, channel: int | None = None, *, pixel_size=None, height_unit: float | None = None,
                    prefix: str = "") -> Measurement:
    """One channel of a measured topography (see module docstring) in SI units.

    ``path``: a file name (str, ``~`` expanded, or ``os.PathLike``); not an open file, whose name,
    date and size the format detection and the cache need. ``channel``: its index (default: the
    file's default channel). ``pixel_size`` (dx or (dx, dy) [m]) and ``height_unit`` [m per height
    unit of the file] override the file's (noted in ``Measurement.notes``); a plain matrix needs
    ``pixel_size`` (``height_unit`` default 1). Errors (``InputError``) and notes name the file and
    the options as ``option(prefix, ...)`` does ("roughness.file", "--pixel-size", ...). A file is
    read once per process while its modification
    time and size stay the same: the same ``Measurement`` (its heights read-only) is returned for
    the same options, up to ``KEPT_BYTES`` of heights kept (the latest read always); a file
    modified less than ``SETTLED`` before is read again (its next change might keep its time).
    """
    if not isinstance(path, (str, os.PathLike)):
        opened = hasattr(path, "read")
        raise InputError(option(prefix, "file"), f"an open {type(path).__name__}" if opened else path,
                         "a file name (str or os.PathLike, e.g. pathlib.Path)"
                         f"{': pass the name of the open file' if opened else ''}")
    path = Path(path).expanduser()
    try:
        found, folder = path.is_file(), path.is_dir()
    except OSError as exc:                        # a name part over 255 bytes
        raise InputError(option(prefix, "file"), path.name[:60], f"cannot be used as a path ({exc.strerror})") from None
    if not found:
        raise InputError(option(prefix, "file"), path.name or str(path),    # (Path(".").name is '')
                         f"{'a folder, not a file' if folder else 'no such file'} "
                         f"({path})")
    stat = path.stat()
    if stat.st_size == 0:     # some readers take it for a 0 x 0 map, then ask for its pixel size
        raise InputError(option(prefix, "file"), path.name, "the file is empty (0 bytes)")
    pair = None if pixel_size is None else check_pair(option(prefix, "pixel_size"), pixel_size, check_positive)
    if height_unit is not None:
        check_positive(option(prefix, "height_unit"), height_unit)
    key, stamp = (path.resolve(), repr(channel), pair, height_unit, prefix), (stat.st_mtime_ns, stat.st_size)
    kept = _KEPT.pop(key, None)
    m = kept[1] if kept is not None and kept[0] == stamp else _read(path, channel, pair, height_unit, prefix)
    after = path.stat()
    if (after.st_mtime_ns, after.st_size) == stamp and time.time_ns() - stamp[0] > SETTLED * 1e9:
        _KEPT[key] = (stamp, m)        # the latest last; a file changed since would have a later mtime
        while len(_KEPT) > 1 and sum(v.heights.nbytes for _, v in _KEPT.values()) > KEPT_BYTES:
            del _KEPT[next(iter(_KEPT))]
    for note in m.notes:
        warnings.warn(note, TopographyWarning, stacklevel=2)
    return m


def _read(path: Path, channel, pair, height_unit: float | None, prefix: str) -> Measurement:
    """``read_topography``'s reading of the file ``path`` (checked), its heights made read-only."""
    if path.suffix.lower() in MATRIX_SUFFIXES:
        if channel not in (None, 0):
            raise InputError(option(prefix, "channel"), channel,
                             f"{path.name} is a plain height matrix: one channel, 0")
        if pair is None:
            raise InputError(option(prefix, "pixel_size"), None, f"{path.name} is a plain height matrix without units: "
                             f"give its pixel size, e.g. {example(prefix, 'pixel_size', '\"0.5 um\"', '0.5e-6')}")
        try:
            h = read_matrix(path) * (1.0 if height_unit is None else height_unit)
        except InputError as exc:
            raise InputError(option(prefix, "file"), path.name, exc.allowed) from None
        if np.any(np.isinf(h)):
            raise InputError(option(prefix, "file"), path.name, "the height matrix holds infinite values (NaN marks an "
                             "undefined point)")
        notes = _height_range(h, path, prefix, "m" if height_unit is None else f"{height_unit:.4g} m")
        notes += _lateral_range(h.shape, *pair, path, prefix)
        h.flags.writeable = False
        return Measurement(h, *pair, path, 0, "matrix", None, tuple(notes))
    ch = _channel(_reader(path, option(prefix, "file")), path, channel, prefix)
    unit = ch.unit if isinstance(ch.unit, str) else None
    notes = []
    try:
        t = ch.topography(**({} if ch.physical_sizes is not None else {"physical_sizes": ch.nb_grid_pts}))
        raw = t.heights()
    except Exception as exc:    # the header was fine, the data is not: still one error naming the file
        raise InputError(option(prefix, "file"), path.name,
                         f"cannot read channel {ch.index} ({_first_line(exc)})") from None
    factor = None if unit is None else surface_topography().Support.UnitConversion.get_unit_conversion_factor(unit, "m")
    if ch.physical_sizes is None or factor is None:
        if pair is None:
            raise InputError(option(prefix, "pixel_size"), None, f"{path.name} gives no lateral "
                             f"{'size' if ch.physical_sizes is None else 'unit'}: give its pixel size, e.g. "
                             f"{example(prefix, 'pixel_size', '\"0.5 um\"', '0.5e-6')}")
        dx, dy = pair
    else:
        dx, dy = (float(v) * factor for v in t.pixel_size)
        if pair is not None:
            notes.append(f"{option(prefix, 'pixel_size', f'{pair[0]:.4g} x {pair[1]:.4g} m')} overrides the file's "
                         f"{dx:.4g} x {dy:.4g} m")
            dx, dy = pair
    if height_unit is not None:
        if factor is not None:
            notes.append(f"{option(prefix, 'height_unit', f'{height_unit:.4g} m')} overrides the file's unit "
                         f"({unit} = {factor:.4g} m)")
        factor = height_unit
    elif factor is None:
        raise InputError(option(prefix, "height_unit"), None, f"{path.name} gives no height unit: give it, e.g. "
                         f"{example(prefix, 'height_unit', '\"nm\" or \"1 um\"', '1e-9')}")
    h = np.ma.filled(np.ma.masked_invalid(np.ma.asarray(raw, dtype=float)), np.nan).T * factor
    notes += _height_range(h, path, prefix, f"{factor:.4g} m", f"channel {ch.index} (\"{ch.name}\")")
    notes += _lateral_range(h.shape, dx, dy, path, prefix)
    h.flags.writeable = False
    return Measurement(h, dx, dy, path, ch.index, str(ch.name), unit, tuple(notes))


def _lateral_range(shape, dx: float, dy: float, path: Path, prefix: str) -> list[str]:
    """Notes if the map [m] is wider than ``WIDEST`` or its pixels finer than ``LOWEST`` (a pixel size
    given in um as m made a 126 x 94 m map without a word: a user trial), or it has fewer than
    ``NARROWEST`` points along a side (300 x 4 points passed with a full PSD: a user trial)."""
    width, height = shape[1] * dx, shape[0] * dy
    name = f"{option(prefix, 'file')} = '{path.name}'"
    out = [] if max(width, height) <= WIDEST and min(dx, dy) >= LOWEST else [
        f"{name}: a map of {width:.3g} x {height:.3g} m (pixels of {dx:.3g} x {dy:.3g} m), "
        f"{'wider than' if max(width, height) > WIDEST else 'pixels finer than'} any measurement's: "
        f"is {option(prefix, 'pixel_size')} in m?"]
    if min(shape) < NARROWEST:
        out.append(f"{name}: a map of {shape[1]} x {shape[0]} points, fewer than {NARROWEST} along a side: a strip, "
                   "whose statistics and PSD across it rest on those few points")
    return out


def _height_range(h: np.ndarray, path: Path, prefix: str, unit: str, what: str = "the height matrix") -> list[str]:
    """A note if the heights [m] (NaN: undefined) reach beyond ``TALLEST`` or stay within ``LOWEST``
    (heights read in the wrong unit, e.g. um as m, m as nm); an InputError if the map is narrower than a ``Surface`` (4 points a
    side), none is defined or their spread overflows."""
    if min(h.shape) < 4:        # a line scan stored as a map, a tiny crop: Surface's error named no file
        raise InputError(option(prefix, "file"), path.name, f"{what} has {h.shape[1]} x {h.shape[0]} points: a "
                         "height map of at least 4 x 4 points is needed")
    if not np.isfinite(h).any():
        raise InputError(option(prefix, "file"), path.name, f"{what} holds no defined height")
    with np.errstate(over="ignore", invalid="ignore"):
        peak, sq = float(np.nanmax(np.abs(h))), float(np.nanstd(h))
    if not np.isfinite(sq):
        raise InputError(option(prefix, "file"), path.name, f"heights up to {peak:.3g} m overflow (one unit of the "
                         f"file = {unit}): is {option(prefix, 'height_unit')} right?")
    if 0 < peak < UNDERFLOW:          # their powers underflow: the statistics divided by zero
        raise InputError(option(prefix, "file"), path.name, f"heights up to {peak:.3g} m underflow (one unit of the "
                         f"file = {unit}): is {option(prefix, 'height_unit')} right?")
    if peak > TALLEST or 0 < peak < LOWEST:
        return [f"{option(prefix, 'file')} = '{path.name}': heights up to {peak:.3g} m (Sq {sq:.3g} m, one unit of "
                f"the file = {unit}), far {'beyond' if peak > TALLEST else 'below'} a rough surface's: is "
                f"{option(prefix, 'height_unit')} right?"]
    return []
