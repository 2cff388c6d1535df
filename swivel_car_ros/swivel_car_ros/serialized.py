"""
Messages as CDR bytes: state messages read and written without rclpy's message objects.

Every control period each node of the lockstep chain takes a ``joint_states`` and answers it.
rclpy turns a received JointState into a Python message (30 us here, its strings and three
arrays set through checking properties), and a published message object into C and CDR
(9 us for an ActuatorCommand, 29 us for an Odometry with its two covariances), against 5 us to
read the fields a node uses at their offsets and 2-5 us to publish bytes. So the hot messages
are subscribed with ``raw=True`` and read here, or serialized once and rewritten in place.

The bytes are little-endian CDR (XCDR1, as rmw_fastrtps and rmw_cyclonedds send ROS types from
x86 and ARM machines): a 4-byte encapsulation header, then each primitive aligned to its size
from the end of that header; a string is a uint32 length (with its NUL) and its bytes, a
sequence a uint32 count and its elements.
"""

from __future__ import annotations

from functools import reduce
import struct
from typing import Callable, NamedTuple, TypeVar

from builtin_interfaces.msg import Time
from rclpy.serialization import serialize_message

CDR_LITTLE_ENDIAN = b'\x00\x01'
CDR_START = 4  # [B] the encapsulation header
# builtin_interfaces/Time (int32 sec, uint32 nanosec) as CDR, what serialize_message gives here.
STAMP_FORMAT = '<iI'

_UINT32 = struct.Struct('<I')

T = TypeVar('T')


def aligned(offset: int, size: int) -> int:
    """Return ``offset`` [B] (from the end of the encapsulation header) aligned to ``size``."""
    return offset + (-offset) % size


def read_header(data: bytes) -> tuple[Time, int]:
    """
    Read the std_msgs/Header a serialized message starts with.

    Returns the stamp and the offset after the header (from the end of the encapsulation
    header).

    Raises
    ------
    ValueError
        Not little-endian plain CDR.

    """
    if data[:2] != CDR_LITTLE_ENDIAN:
        raise ValueError(f'not little-endian plain CDR: encapsulation {bytes(data[:2]).hex()}')
    sec, nanosec, frame_id_length = struct.unpack_from('<iII', data, CDR_START)
    return Time(sec=sec, nanosec=nanosec), 12 + frame_id_length


def read_logged(logger, read: Callable[[bytes], T], data: bytes, topic: str) -> T | None:
    """
    Return ``read(data)``, or None once ``logger`` has said why the message is ignored.

    ``topic`` names the message in the log line (at most one every 5 s). A message shorter
    than its fields (``struct.error`` from any reader) is refused as a malformed one is.
    """
    try:
        return read(data)
    except (ValueError, struct.error) as error:
        logger.error(f'{topic} ignored: {error}', throttle_duration_sec=5.0)
        return None


class JointStateView(NamedTuple):
    """The fields of a sensor_msgs/JointState a controller or an odometry reads."""

    stamp: Time
    name: tuple[str, ...]
    position: tuple[float, ...]  # [rad] or [m]
    velocity: tuple[float, ...]  # [rad/s] or [m/s]; may be empty


def read_joint_state(data: bytes) -> JointStateView:
    """
    Read a serialized sensor_msgs/JointState: stamp, names, positions, velocities.

    Raises
    ------
    ValueError
        Not little-endian plain CDR, or shorter than its counts say.

    """
    stamp, offset = read_header(data)
    unpack_count = _UINT32.unpack_from
    # Offsets from the start of the data: CDR aligns from the end of the encapsulation header.
    at = CDR_START + aligned(offset, 4)
    try:
        (count,) = unpack_count(data, at)
        at += 4
        names = []
        for _ in range(count):
            (length,) = unpack_count(data, at)
            names.append(data[at + 4:at + 3 + length].decode())
            at += 4 + length + (-length) % 4
        arrays = []
        for _ in range(2):  # position, velocity
            (count,) = unpack_count(data, at)
            at += 4
            if count:  # Fast CDR aligns the elements, not the count: none, no padding
                at += (CDR_START - at) % 8
            arrays.append(struct.unpack_from(f'<{count}d', data, at))
            at += 8 * count
    except (struct.error, UnicodeDecodeError) as error:
        raise ValueError(f'malformed JointState: {error}') from None
    return JointStateView(stamp, tuple(names), *arrays)


def _field(parent, name: str):
    return parent[int(name)] if name.isdigit() else getattr(parent, name)


class SerializedMessage:
    """
    A message serialized once, whose changing fields are rewritten in place.

    Parameters
    ----------
    msg
        The message with its constant fields (frame ids, names) set.
    fields : tuple of (str, tuple of str)
        Groups of fields consecutive in the serialized message, each a struct format and the
        fields' dotted paths (a number is an element of a sequence: 'transforms.0.header'),
        rewritten with ``pack(index of the group, *values)``. A float64[] field is a group of
        one path and the format ``'<Nd'``: its length N is fixed from then on.

    """

    def __init__(self, msg, fields: tuple[tuple[str, tuple[str, ...]], ...]) -> None:
        # Set every group to sentinel values, serialize, and find where they landed.
        sentinel = 0x5E7CA100  # a clash with other bytes fails the count check below
        expected = []
        for fmt, paths in fields:
            layout = struct.Struct(fmt)
            count = len(layout.unpack(bytes(layout.size)))
            values = [sentinel + k + (0.25 if fmt.endswith('d') else 0) for k in range(count)]
            sentinel += count
            for path, value in zip(paths, [values] if len(paths) < count else values,
                                   strict=True):
                *parents, name = path.split('.')
                setattr(reduce(_field, parents, msg), name, value)
            expected.append((layout, layout.pack(*values)))
        self._data = bytearray(serialize_message(msg))
        self._groups = []
        for layout, packed in expected:
            if self._data.count(packed) != 1:
                raise ValueError(f'{type(msg).__name__}: the fields {fields} are not '
                                 'consecutive in its serialized form')
            self._groups.append((layout.pack_into, self._data.index(packed)))

    def pack(self, index: int, *values) -> None:
        """Write ``values`` into the field group ``index`` (in the order of ``fields``)."""
        pack_into, offset = self._groups[index]
        pack_into(self._data, offset, *values)

    def serialized(self) -> bytes:
        """Return the message as it stands, serialized."""
        return bytes(self._data)
