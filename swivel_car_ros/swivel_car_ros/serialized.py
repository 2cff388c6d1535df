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
sequence a uint32 count and its elements. ``MessageReader`` lays a message type's fields out
from its definition (the ``.msg`` as rosidl generated it), so a reader follows the message
when a field is added.
"""

from __future__ import annotations

from functools import reduce
import importlib
import struct
from typing import Callable, NamedTuple, TypeVar

from builtin_interfaces.msg import Time
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState

CDR_LITTLE_ENDIAN = b'\x00\x01'
CDR_START = 4  # [B] the encapsulation header
# builtin_interfaces/Time (int32 sec, uint32 nanosec) as CDR, what serialize_message gives here.
STAMP_FORMAT = '<iI'

_UINT32 = struct.Struct('<I')

T = TypeVar('T')


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


# CDR primitives as struct format characters (rosidl's type names).
_PRIMITIVES = {'boolean': '?', 'octet': 'B', 'char': 'B', 'uint8': 'B', 'int8': 'b',
               'uint16': 'H', 'int16': 'h', 'uint32': 'I', 'int32': 'i', 'uint64': 'Q',
               'int64': 'q', 'float': 'f', 'double': 'd'}


def _element(kind: str) -> str:
    """Return the struct character of a primitive, 's' for a string (bounded or not)."""
    if kind == 'string' or kind.startswith('string<'):
        return 's'
    if kind in _PRIMITIVES:
        return _PRIMITIVES[kind]
    raise ValueError(f'{kind} is not a primitive or a string')


def _leaves(message_type, prefix: str = ''):
    """
    Yield the fields of ``message_type`` in serialized order, nested messages flattened.

    Each is (dotted path, kind, struct character, count): kind 'fixed' (a primitive,
    ``count`` of them for a fixed array), 'string' or 'sequence' (of primitives or strings).
    """
    for name, kind in message_type.get_fields_and_field_types().items():
        path = prefix + name
        if kind.startswith('sequence<'):
            yield path, 'sequence', _element(kind[9:-1].split(',')[0]), 0
        elif '/' in kind and '[' not in kind:
            package, _, type_name = kind.partition('/')
            nested = getattr(importlib.import_module(f'{package}.msg'), type_name)
            yield from _leaves(nested, path + '.')
        elif kind.endswith(']') and kind[:kind.index('[')] in _PRIMITIVES:
            base, _, count = kind[:-1].partition('[')
            yield path, 'fixed', _PRIMITIVES[base], int(count)
        else:
            character = _element(kind)
            yield path, 'string' if character == 's' else 'fixed', character, 1


def _fixed_run(run: list, wanted: set):
    """
    Return a reader of consecutive primitives, the first the most aligned of them.

    Aligned at the first, the padding inside the run is fixed: one struct does it all.
    """
    size = struct.calcsize(run[0][2])
    layout, position = '<', 0
    for path, _, character, count in run:
        item = struct.calcsize(character)
        padding = (-position) % item
        if path in wanted and count != 1:
            raise ValueError(f'{path} is an array: read its elements from the messages')
        layout += f'{padding}x' + (character if path in wanted else f'{item * count}x')
        position += padding + item * count
    unpack, length = struct.Struct(layout).unpack_from, struct.calcsize(layout)

    def read(data, at: int, out: list) -> int:
        at += (CDR_START - at) % size
        out += unpack(data, at)
        return at + length

    def skip(data, at: int, out: list) -> int:
        return at + (CDR_START - at) % size + length
    return read if wanted.intersection(path for path, *_ in run) else skip


def _unpack_string(data, at: int) -> tuple[str, int]:
    at += (CDR_START - at) % 4
    (length,) = _UINT32.unpack_from(data, at)  # with its NUL
    return bytes(data[at + 4:at + 3 + length]).decode(), at + 4 + length


def _skip_string(data, at: int, out: list) -> int:
    at += (CDR_START - at) % 4
    return at + 4 + _UINT32.unpack_from(data, at)[0]


def _variable(character: str, kind: str, keep: bool):
    """Return a reader of a string or a sequence, that keeps its value if ``keep``."""
    def string(data, at: int, out: list) -> int:
        text, at = _unpack_string(data, at)
        if keep:
            out.append(text)
        return at

    def strings(data, at: int, out: list) -> int:
        at += (CDR_START - at) % 4
        (count,) = _UINT32.unpack_from(data, at)
        at += 4
        texts = []
        for _ in range(count):
            text, at = _unpack_string(data, at)
            texts.append(text)
        if keep:
            out.append(tuple(texts))
        return at

    def primitives(data, at: int, out: list) -> int:
        at += (CDR_START - at) % 4
        (count,) = _UINT32.unpack_from(data, at)
        at += 4
        if count:  # Fast CDR aligns the elements, not the count: none, no padding
            at += (CDR_START - at) % size
        if keep:
            out.append(struct.unpack_from(f'<{count}{character}', data, at))
        return at + size * count
    if kind == 'string':
        return string if keep else _skip_string
    if character == 's':
        return strings
    size = struct.calcsize(character)
    return primitives


class MessageReader:
    """
    Read chosen fields of a serialized message at offsets laid out from its definition.

    Parameters
    ----------
    message_type
        A rosidl message class; its ``get_fields_and_field_types`` (the ``.msg``) gives the
        order and types of the fields, nested messages included.
    paths : tuple of str
        The fields to read, as dotted paths ('header.stamp.sec', 'pose.pose.position.x'): a
        primitive, a string or a sequence (read as a tuple), in the order of the message.
        Called with the bytes, the reader returns their values.

    Raises
    ------
    ValueError
        A path that is not a primitive, string or sequence field of the message, paths out of
        order, or a field of a type laid out otherwise (an array or a sequence of messages).

    """

    def __init__(self, message_type, paths: tuple[str, ...]) -> None:
        self._name = message_type.__name__
        leaves = list(_leaves_until(message_type, set(paths)))
        if [path for path, *_ in leaves if path in paths] != list(paths):
            raise ValueError(f'{self._name}: give the paths in the order of its fields')
        wanted, self._readers, run = set(paths), [], []
        for leaf in leaves:
            if leaf[1] == 'fixed' and run and struct.calcsize(leaf[2]) <= struct.calcsize(
                    run[0][2]):
                run.append(leaf)
                continue
            if run:
                self._readers.append(_fixed_run(run, wanted))
            run = [leaf] if leaf[1] == 'fixed' else []
            if not run:
                self._readers.append(_variable(leaf[2], leaf[1], leaf[0] in wanted))
        if run:
            self._readers.append(_fixed_run(run, wanted))

    def __call__(self, data: bytes) -> tuple:
        """
        Return the fields' values.

        Raises
        ------
        ValueError
            Not little-endian plain CDR, or shorter than its fields or counts say.

        """
        if data[:2] != CDR_LITTLE_ENDIAN:
            raise ValueError(
                f'not little-endian plain CDR: encapsulation {bytes(data[:2]).hex()}')
        out, at = [], CDR_START
        try:
            for read in self._readers:
                at = read(data, at, out)
        except (struct.error, UnicodeDecodeError) as error:
            raise ValueError(f'malformed {self._name}: {error}') from None
        return tuple(out)


def _leaves_until(message_type, paths: set[str]):
    """Yield the leaves of ``message_type`` up to the last of ``paths``; raise on unknown."""
    leaves = list(_leaves(message_type))
    known = {path for path, *_ in leaves}
    if not paths <= known:
        raise ValueError(f'{message_type.__name__} has no field(s) '
                         f'{", ".join(sorted(paths - known))}')
    last = max(index for index, (path, *_) in enumerate(leaves) if path in paths)
    return leaves[:last + 1]


class JointStateView(NamedTuple):
    """The fields of a sensor_msgs/JointState a controller or an odometry reads."""

    stamp: Time
    name: tuple[str, ...]
    position: tuple[float, ...]  # [rad] or [m]
    velocity: tuple[float, ...]  # [rad/s] or [m/s]; may be empty


_JOINT_STATE = MessageReader(
    JointState, ('header.stamp.sec', 'header.stamp.nanosec', 'name', 'position', 'velocity'))


def read_joint_state(data: bytes) -> JointStateView:
    """
    Read a serialized sensor_msgs/JointState: stamp, names, positions, velocities.

    Raises
    ------
    ValueError
        Not little-endian plain CDR, or shorter than its counts say.

    """
    sec, nanosec, *arrays = _JOINT_STATE(data)
    return JointStateView(Time(sec=sec, nanosec=nanosec), *arrays)


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
