"""The channel map of a file of FRFs: which dataset 58 holds each sensor's FRF, and in which accelerance units.

Each sensor of ``structure.sensors`` is matched to one FRF by its ID line 1 (``id1``, the sensor's name unless a
channel map says otherwise) or by its response node and direction. The FRFs must be force-normalised accelerance
(m/s^2/N, or g/N converted with 9.80665): a unit a map states, or a file's label, is brought to the spelling of
``ACCELERANCE_UNITS`` by ``accelerance_unit``. Nothing is guessed: a map that leaves a sensor out, maps one twice or
states other units is refused. The config's checks read the map here, without reading the file.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..io import RawDataError

# force-normalised accelerance, with the factor to m/s^2/N
ACCELERANCE_UNITS = {"m/s^2/N": 1.0, "g/N": 9.80665, "mm/s^2/N": 1.0e-3}
_UNIT_SPELLINGS = {
    "m/s2/N": "m/s^2/N",
    "(m/s^2)/N": "m/s^2/N",
    "(m/s2)/N": "m/s^2/N",
    "m/s**2/N": "m/s^2/N",
    "m/s/s/N": "m/s^2/N",
    "m s-2 N-1": "m/s^2/N",
    "m/(s^2 N)": "m/s^2/N",
    "m/N/s^2": "m/s^2/N",
    "g0/N": "g/N",
    "gn/N": "g/N",
    "mm/s2/N": "mm/s^2/N",
    "(mm/s^2)/N": "mm/s^2/N",
}
# a unit label that states no unit, as files write it
NO_LABEL = ("", "NONE", "none", "-")


@dataclass(frozen=True)
class FrfSensor:
    """One sensor of the FRF file: its name and position, the FRF dataset that holds it and the units the map states.

    Attributes
    ----------
    name
        The sensor's name (structure.sensors.names).
    position_m
        Its distance from the clamp (structure.sensors.positions_m) [m].
    channel
        ID line 1 (id1) of the FRF dataset that holds it; None where it is found by its node.
    node
        Response node of the FRF dataset that holds it; None where it is found by its id1.
    direction
        Response direction of that dataset; None for any.
    units
        The units the channel map states for its FRF, in the spelling of ``ACCELERANCE_UNITS``; None where the map
        states none.
    """

    name: str
    position_m: float
    channel: str | None = None
    node: int | None = None
    direction: int | None = None
    units: str | None = None

    def describe(self) -> str:
        """Return the FRF dataset that holds the sensor, in words for messages: its id1, or its response node.

        Returns
        -------
        description : str
            ``id1 'name'``, or ``response node n`` with ``direction d`` where one is given.
        """
        if self.channel is not None:
            return f"id1 {self.channel!r}"
        return f"response node {self.node}" + ("" if self.direction is None else f" direction {self.direction}")


def accelerance_unit(label: str | None) -> str | None:
    """Return a unit label of an FRF in the spelling of ACCELERANCE_UNITS / OTHER_KINDS (None for no label).

    Parameters
    ----------
    label
        A unit label as a file or a channel map writes it (``m/s2/N``, ``(m/s^2)/N``, ``g0/N``...); None, empty,
        ``NONE`` or ``-`` for no label.

    Returns
    -------
    unit : str | None
        The label with its white space normalised and known spellings mapped to the table's (an unknown label comes
        back as it is); None for no label.
    """
    if label is None or str(label).strip() in NO_LABEL:
        return None
    s = " ".join(str(label).split())
    s = s.replace(" / ", "/")
    return _UNIT_SPELLINGS.get(s, s)


def _map_entry(entry, i: int, names: list, positions: list, where: str) -> FrfSensor:
    key = f"{where}: channels.sensors[{i}]"
    if not isinstance(entry, Mapping) or not entry.get("name"):
        raise RawDataError(f"{key}: give a mapping with the sensor's name and its channel (id1) or node")
    name = str(entry["name"])
    if name not in names:
        raise RawDataError(f"{key}: sensor {name!r} is not one of structure.sensors.names {names}")
    pos = positions[names.index(name)]
    if entry.get("position_m") is not None and abs(float(entry["position_m"]) - pos) > 1e-3:
        raise RawDataError(
            f"{key}: position_m = {entry['position_m']} m but structure.sensors puts {name} at {pos} m; "
            "make the model's sensor layout (config) match the test"
        )
    channel, node = entry.get("channel"), entry.get("node")
    if (channel is None) == (node is None):
        raise RawDataError(f"{key}: give either channel (the FRF's id1) or node (its response node), not both")
    units = entry.get("units")
    if units is not None and accelerance_unit(units) not in ACCELERANCE_UNITS:
        raise RawDataError(
            f"{key}: units = {units!r}; give force-normalised accelerance: {', '.join(ACCELERANCE_UNITS)}"
        )
    direction = entry.get("direction")
    return FrfSensor(
        name,
        pos,
        None if channel is None else str(channel),
        None if node is None else int(node),
        None if direction is None else int(direction),
        None if units is None else accelerance_unit(units),
    )


def frf_sensor_map(block: Mapping, where: str, structure_cfg: Mapping) -> tuple:
    """Return the FrfSensor of every structure sensor, in structure order.

    From ``channels.sensors`` of the config block, or, without a map, the FRF whose id1 is the sensor's name.

    Parameters
    ----------
    block
        The config block of the FRF file (``random_test``); its ``channels`` (``{sensors: [{name, channel or node,
        direction, units, position_m}]}``) is read.
    where
        The block's name in the config, named in the messages.
    structure_cfg
        The config's ``structure`` block; ``sensors.names`` and ``sensors.positions_m`` [m] are read.

    Returns
    -------
    sensors : tuple
        One FrfSensor per sensor of ``structure_cfg``, in its order.

    Raises
    ------
    RawDataError
        When the channel map is not of that form (or names a force), maps a sensor twice, or leaves one out; an
        entry that names no known sensor, a position other than the structure's, both or neither of channel and
        node, or units other than accelerance is refused too.
    """
    names = [str(n) for n in structure_cfg["sensors"]["names"]]
    positions = [float(x) for x in structure_cfg["sensors"]["positions_m"]]
    chans = block.get("channels")
    if not chans:
        return tuple(FrfSensor(n, p, channel=n) for n, p in zip(names, positions))
    if not isinstance(chans, Mapping) or "force" in chans or not isinstance(chans.get("sensors"), (list, tuple)):
        raise RawDataError(
            f"{where}: an FRF file's channel map is channels: {{sensors: [{{name, channel or node, units}}]}} "
            "(no force: the FRFs are already normalised by it)"
        )
    mapped = {}
    for i, entry in enumerate(chans["sensors"]):
        s = _map_entry(entry, i, names, positions, where)
        if s.name in mapped:
            raise RawDataError(f"{where}: channels.sensors maps {s.name} twice; give each sensor once")
        mapped[s.name] = s
    missing = [n for n in names if n not in mapped]
    if missing:
        raise RawDataError(
            f"{where}: channels.sensors does not map {missing} of structure.sensors.names; "
            "the modal fit needs an FRF at every sensor of the model"
        )
    return tuple(mapped[n] for n in names)
