"""The channel map of an import: which channel is the force, which the accelerometers, their units and positions.

The map says which channel of the file is the force and which are the accelerometers, in which units, with which
sensitivity and at which position. Nothing is guessed: every channel names its units; a channel stored as a voltage
(``V`` or ``mV``) needs its sensitivity and the sensitivity's units (``mV/N``, ``mV/g``, ``V/(m/s^2)``...). Where the
file also states a unit, it must agree with the map.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..io import TIME_UNITS, RawDataError

# physical units accepted per quantity, with the factor to SI (N, m/s^2)
PHYSICAL = {
    "force": {"N": 1.0, "kN": 1.0e3, "lbf": 4.4482216152605},
    "acceleration": {"m/s^2": 1.0, "g": 9.80665, "mm/s^2": 1.0e-3},
}
# electrical units, factor to mV
ELECTRICAL = {"mV": 1.0, "V": 1.0e3}
# spellings of the same unit met in files, mapped to the names above
ALIASES = {
    "m/s2": "m/s^2",
    "m s-2": "m/s^2",
    "m/s**2": "m/s^2",
    "m/s/s": "m/s^2",
    "ms-2": "m/s^2",
    "newton": "N",
    "n": "N",
    "g0": "g",
    "gn": "g",
    "mv": "mV",
    "v": "V",
    "volt": "V",
    "volts": "V",
    "kn": "kN",
    "mm/s2": "mm/s^2",
}

FORMATS = ("netcdf", "uff58", "tdms", "csv")


def canonical_unit(label: str) -> str:
    """Return a unit label as written in a file in the spelling of PHYSICAL / ELECTRICAL.

    Parameters
    ----------
    label
        The unit as a file or a channel map writes it ("m/s2", "newton", "mv", ...).

    Returns
    -------
    unit : str
        Its spelling in ``ALIASES``' targets, or the label stripped where it has no alias.
    """
    s = str(label).strip()
    return ALIASES.get(s, ALIASES.get(s.lower(), s))


@dataclass(frozen=True)
class ChannelSpec:
    """One channel of the file: its role, its name in the file, units, sensitivity and position.

    Attributes
    ----------
    role
        "force", or the sensor's name.
    channel
        The channel's name in the file: UFF58 id1, TDMS "group/channel", CSV column.
    units
        The units the file stores it in, canonical (``canonical_unit``): a key of PHYSICAL's quantity or of
        ELECTRICAL.
    sensitivity
        For a channel stored as a voltage: its sensitivity [unit of sensitivity_units]; None otherwise.
    sensitivity_units
        The sensitivity's units, "<V or mV>/<physical unit>" (``mV/N``, ``mV/g``); None where no sensitivity.
    position_m
        A sensor's distance from the clamp [m]; None for the force.
    """

    role: str
    channel: str
    units: str
    sensitivity: float | None = None
    sensitivity_units: str | None = None
    position_m: float | None = None

    @property
    def quantity(self) -> str:
        """The quantity the channel measures: "force" for the force channel, otherwise "acceleration"."""
        return "force" if self.role == "force" else "acceleration"

    def factor(self) -> float:
        """Return the factor from the file's numbers to SI (N or m/s^2).

        Returns
        -------
        factor : float
            SI value per file number: [N/unit of units] for the force, [m/s^2/unit of units] for an accelerometer.
        """
        phys = PHYSICAL[self.quantity]
        if self.units in phys:
            return phys[self.units]
        num, den = self.sensitivity_units.split("/", 1)
        den = den.strip().strip("()")
        return ELECTRICAL[self.units] / (self.sensitivity * ELECTRICAL[num.strip()]) * phys[den]


@dataclass(frozen=True)
class ImportSpec:
    """What to import and how: format, file, channel map, declared rates, CSV time column and the map's place.

    Attributes
    ----------
    format
        The file's format, one of ``FORMATS``.
    file
        The file's path.
    channels
        The channel map (``ChannelSpec``), the force first, then the accelerometers.
    sampling_rate_hz
        The declared sampling rate [Hz]; None where the file states it.
    excitation_frequency_hz
        The declared excitation frequency [Hz]; None where the file states it.
    time_column
        The CSV's time column; None where the map names none.
    where
        Where the map was written, for messages.
    time_units
        The CSV time column's unit: s, ms or us (contactid.io's time units).
    """

    format: str
    file: str
    channels: tuple
    sampling_rate_hz: float | None
    excitation_frequency_hz: float | None
    time_column: str | None
    where: str
    time_units: str = "s"  # the CSV time column's unit: s, ms or us (contactid.io's time units)

    @property
    def force(self) -> ChannelSpec:
        """The force channel (the map's first)."""
        return self.channels[0]

    @property
    def sensors(self) -> tuple:
        """The accelerometer channels (ChannelSpec), in the map's order."""
        return self.channels[1:]


def _channel(entry, role: str, where: str) -> ChannelSpec:
    if not isinstance(entry, Mapping):
        raise RawDataError(f"{where}: {role}: give a mapping with 'channel' and 'units', got {entry!r}")
    quantity = "force" if role == "force" else "acceleration"
    ch = entry.get("channel")
    if ch is None or str(ch).strip() == "":
        raise RawDataError(f"{where}: {role}.channel is missing: name the channel of the file that holds it")
    units = entry.get("units")
    if units is None:
        raise RawDataError(
            f"{where}: {role}.units is missing: state the units the file stores "
            f"({', '.join(PHYSICAL[quantity])}, or V / mV with a sensitivity); units are never guessed"
        )
    units = canonical_unit(units)
    sens, sens_units = entry.get("sensitivity"), entry.get("sensitivity_units")
    if units in ELECTRICAL:
        if sens is None or sens_units is None:
            raise RawDataError(
                f"{where}: {role} is stored in {units}: give sensitivity and sensitivity_units "
                f"(for example sensitivity: 10.2, sensitivity_units: mV/{'N' if quantity == 'force' else 'g'})"
            )
        sens = _positive_or_none(entry, "sensitivity", f"{where}: {role}")
        parts = str(sens_units).split("/", 1)
        den = parts[1].strip().strip("()") if len(parts) == 2 else ""
        if len(parts) != 2 or parts[0].strip() not in ELECTRICAL or den not in PHYSICAL[quantity]:
            raise RawDataError(
                f"{where}: {role}.sensitivity_units = {sens_units!r}: give <V or mV>/<unit>, the unit one of "
                f"{', '.join(PHYSICAL[quantity])} (for example mV/{'N' if quantity == 'force' else 'g'})"
            )
        sens_units = f"{parts[0].strip()}/{den}"
    elif units not in PHYSICAL[quantity]:
        raise RawDataError(
            f"{where}: {role}.units = {entry.get('units')!r} is not a {quantity} unit; give one of "
            f"{', '.join(PHYSICAL[quantity])}, or V / mV with a sensitivity"
        )
    elif sens is not None:
        raise RawDataError(
            f"{where}: {role} has a sensitivity but units {units}: a sensitivity applies to V or mV only"
        )
    pos = entry.get("position_m")
    if role != "force":
        if pos is None:
            raise RawDataError(f"{where}: sensor {role}: position_m is missing (m from the clamp)")
        try:
            pos = float(pos)
        except (TypeError, ValueError):
            raise RawDataError(
                f"{where}: sensor {role}: position_m = {pos!r}: give a number (m from the clamp)"
            ) from None
    return ChannelSpec(role, str(ch), units, sens, sens_units, pos)


def _positive_or_none(block: Mapping, key: str, where: str) -> float | None:
    v = block.get(key)
    if v is None:
        return None
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise RawDataError(f"{where}: {key} = {v!r}: give a positive number") from None
    if not (v > 0 and v < float("inf")):
        raise RawDataError(f"{where}: {key} = {v!r}: give a positive number")
    return v


def import_spec(block: Mapping, where: str, fmt: str, file: str) -> ImportSpec:
    """Parse a channel map: the config block of a UFF58 or TDMS import, or a CSV's sidecar.

    Parameters
    ----------
    block
        The channel map: reads ``channels: {force: {...}, sensors: [{name, channel, units, position_m, ...}, ...]}``
        (each channel's ``channel``, ``units``, ``sensitivity``, ``sensitivity_units``, ``position_m`` [m]),
        ``sampling_rate_hz`` [Hz], ``excitation_frequency_hz`` [Hz], ``time_column`` and ``time_units`` (CSV).
    where
        Where the map was written, for messages.
    fmt
        The file's format: "uff58", "tdms" or "csv".
    file
        The file's path.

    Returns
    -------
    spec : ImportSpec
        The parsed map.

    Raises
    ------
    RawDataError
        When the format is not one of them, the map is not a mapping, gives no force or sensors, a sensor has no
        name, names or channels repeat, the time units are not s, ms or us, or a channel's entry is incomplete or
        inconsistent (units, sensitivity, position), or a rate is not a positive number.
    """
    if fmt not in FORMATS[1:]:
        raise RawDataError(f"{where}: format = {fmt!r}; give one of {', '.join(FORMATS)}")
    if not isinstance(block, Mapping):
        raise RawDataError(f"{where}: expected a mapping with 'channels', got {type(block).__name__}")
    chans = block.get("channels")
    if not isinstance(chans, Mapping) or "force" not in chans or not chans.get("sensors"):
        raise RawDataError(
            f"{where}: channels must give 'force' and a list 'sensors' (see config/README.md, importers)"
        )
    sensors = chans["sensors"]
    if not isinstance(sensors, (list, tuple)):
        raise RawDataError(f"{where}: channels.sensors must be a list of {{name, channel, units, position_m}}")
    specs = [_channel(chans["force"], "force", where)]
    for i, s in enumerate(sensors):
        name = s.get("name") if isinstance(s, Mapping) else None
        if not name:
            raise RawDataError(f"{where}: channels.sensors[{i}].name is missing (the sensor's name, e.g. a1)")
        specs.append(_channel(s, str(name), where))
    names = [s.role for s in specs[1:]]
    if len(set(names)) != len(names):
        raise RawDataError(f"{where}: sensor names repeat ({names}); give each its own")
    used = [s.channel for s in specs]
    dup = sorted({c for c in used if used.count(c) > 1})
    if dup:
        raise RawDataError(f"{where}: channel(s) {dup} are mapped twice; each role needs its own channel")
    tc = block.get("time_column")
    tu = str(block.get("time_units", "s")).strip()
    if tu not in TIME_UNITS:
        raise RawDataError(f"{where}: time_units = {tu!r}; give s, ms or us (the unit of the time column)")
    return ImportSpec(
        fmt,
        str(file),
        tuple(specs),
        _positive_or_none(block, "sampling_rate_hz", where),
        _positive_or_none(block, "excitation_frequency_hz", where),
        str(tc) if tc else None,
        where,
        tu,
    )


def check_file_unit(spec: ChannelSpec, label: str | None, path: str) -> None:
    """Check that a unit stated in the file agrees with the map's.

    An empty or absent label says nothing.

    Parameters
    ----------
    spec
        The channel's entry in the map.
    label
        The unit the file states for the channel; None (or empty, "NONE", "-") where it states none.
    path
        The file's path, for the message.

    Raises
    ------
    RawDataError
        When the file's unit differs from the map's.
    """
    if label is None or str(label).strip() in ("", "NONE", "none", "-"):
        return
    found = canonical_unit(label)
    if found != spec.units:
        raise RawDataError(
            f"{path}: channel {spec.channel!r} ({spec.role}) is labelled {str(label).strip()!r} in the "
            f"file but the channel map says units: {spec.units}; correct the map (or the file)"
        )
