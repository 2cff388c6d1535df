"""
Recording as a rosbag2 bag with MCAP storage (``metadata.yaml`` plus one ``.mcap``).

Through the ``rosbags`` library, ROS-free: the recorder node hands it serialized (CDR)
messages.

Message definitions are embedded in the file as ``ros2msg`` schemas, the way ``ros2 bag
record`` writes them, so ``ros2 bag info/play``, Foxglove and any MCAP reader decode the bag
without the stack's interfaces installed. Definitions come from rosbags' Jazzy type store,
and, for types it does not know (the stack's own), from the ``.msg`` and ``.action`` files the
interface packages install under ``share/<package>/``.
"""

from __future__ import annotations

from dataclasses import dataclass
import os
from pathlib import Path
import re
from typing import Callable, Iterable

from rosbags.interfaces import Nodetype, Qos
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import get_types_from_msg, get_typestore, Stores

BAG_VERSION = 9  # rosbag2 metadata version that Jazzy's `ros2 bag` writes


class UnknownTypeError(LookupError):
    """No definition can be found for a message type."""


class MessageDefinitions:
    """
    Message definitions (``ros2msg`` text) and type hashes (RIHS01) by type name.

    Parameters
    ----------
    share_directory : callable
        Package name -> its installed share directory (``ament_index_python``'s
        ``get_package_share_directory``); raises LookupError for an unknown package.

    """

    def __init__(self, share_directory: Callable[[str], str | Path]) -> None:
        self._share_directory = share_directory
        self.typestore = get_typestore(Stores.ROS2_JAZZY)

    def definition(self, msgtype: str) -> tuple[str, str]:
        """
        Return (message definition with every nested type, RIHS01 hash) of a type.

        The type is named as e.g. 'sensor_msgs/msg/JointState'.

        Raises
        ------
        UnknownTypeError
            Neither the type store nor the installed interface files define it (or a type it
            nests).

        """
        pending = [msgtype]
        while pending:
            name = pending.pop()
            if name not in self.typestore.fielddefs:
                types = self._types_from_files(name)
                self.typestore.register(types)
                pending += [nested for _, fields in types.values()
                            for nested in _nested_types(fields)]
            else:
                pending += [nested for nested in _nested_types(self.typestore.fielddefs[name][1])
                            if nested not in self.typestore.fielddefs]
        try:
            return (self.typestore.generate_msgdef(msgtype, ros_version=2)[0],
                    self.typestore.hash_rihs01(msgtype))
        except (AssertionError, KeyError, ValueError) as error:
            raise UnknownTypeError(f'{msgtype}: cannot write its definition ({error!r})') \
                from None

    def _types_from_files(self, msgtype: str) -> dict:
        try:
            package, kind, name = msgtype.split('/')
            share = Path(self._share_directory(package))
        except (ValueError, LookupError) as error:
            raise UnknownTypeError(f'{msgtype}: no installed interface package ({error})') \
                from None
        if kind == 'msg':
            path = share / 'msg' / f'{name}.msg'
            if path.is_file():
                return get_types_from_msg(path.read_text(), msgtype)
        elif kind == 'action' and name.endswith('_FeedbackMessage'):
            # The only action type on a topic: goal id + the .action file's third section.
            # rosbags writes nested types as msg types only, so the feedback is nested as
            # <package>/msg/<Action>_Feedback: decoders need only the text to be consistent.
            action = name.removesuffix('_FeedbackMessage')
            path = share / 'action' / f'{action}.action'
            if path.is_file():
                sections = re.split(r'^---\s*$', path.read_text(), flags=re.MULTILINE)
                if len(sections) == 3:
                    feedback = f'{package}/msg/{action}_Feedback'
                    return get_types_from_msg(sections[2], feedback) | get_types_from_msg(
                        f'unique_identifier_msgs/UUID goal_id\n{feedback} feedback', msgtype)
        raise UnknownTypeError(f'{msgtype}: no definition installed under {share}')


def _nested_types(fields: Iterable) -> list[str]:
    names = []
    for _, (nodetype, detail) in fields:
        if nodetype in (Nodetype.ARRAY, Nodetype.SEQUENCE):
            nodetype, detail = detail[0]
        if nodetype == Nodetype.NAME:
            names.append(detail)
    return names


@dataclass(frozen=True)
class TopicRecord:
    """What one topic of a closed bag holds."""

    topic: str
    msgtype: str
    count: int


class BagWriter:
    """
    A rosbag2 bag with MCAP storage, written message by message.

    Stops writing, and closes the bag so that it stays readable, when the disk holding it has
    less than ``min_free_space`` left (a chunk is kept in memory until 1 MiB, then written with
    the file's index at close, so the margin must exceed that). A write that fails anyway (a
    disk filled by someone else between two checks) also stops it.

    Parameters
    ----------
    path : Path
        The bag's directory; must not exist yet (its parent is created).
    definitions : MessageDefinitions
        Where message definitions come from.
    min_free_space : int
        Free space to leave on the disk. # [bytes]
    free_space : callable
        Path -> free bytes on its file system (``os.statvfs`` by default).

    Raises
    ------
    ValueError
        ``path`` exists, or ``min_free_space`` is negative.

    """

    def __init__(self, path: Path, definitions: MessageDefinitions, min_free_space: int,
                 free_space: Callable[[Path], int] | None = None) -> None:
        if path.exists():
            raise ValueError(f'{path} exists already: give a new bag directory')
        if not min_free_space >= 0:
            raise ValueError(f'min_free_space must be >= 0, got {min_free_space!r}')
        self.path = path
        self._definitions = definitions
        self._min_free_space = min_free_space
        self._free_space = free_space or _statvfs_free
        self._writer: Writer | None = None
        self._connections: dict[str, object] = {}
        self.stopped: str | None = None  # why writing stopped, once it has
        self.records: list[TopicRecord] = []  # what each topic holds, once closed

    @property
    def is_open(self) -> bool:
        return self._writer is not None

    def create(self) -> None:
        """
        Create the bag (directory, metadata at close, the .mcap).

        Raises
        ------
        OSError
            The directory cannot be created.

        """
        self.path.parent.mkdir(parents=True, exist_ok=True)
        writer = Writer(self.path, version=BAG_VERSION, storage_plugin=StoragePlugin.MCAP)
        writer.open()
        self._writer = writer

    def add_topic(self, topic: str, msgtype: str, qos: list[Qos]) -> None:
        """
        Register a topic before its first message.

        Raises
        ------
        UnknownTypeError
            No definition for ``msgtype``.

        """
        msgdef, rihs01 = self._definitions.definition(msgtype)
        assert self._writer is not None, 'open() first'
        self._connections[topic] = self._writer.add_connection(
            topic, msgtype, msgdef=msgdef, rihs01=rihs01, offered_qos_profiles=qos)

    def write(self, topic: str, timestamp: int, data: bytes) -> bool:
        """
        Append one serialized message received at ``timestamp`` [ns].

        Returns False once writing has stopped (then ``stopped`` says why).
        """
        if self.stopped is not None or self._writer is None:
            return False
        free = self._free_space(self.path)
        if free < self._min_free_space:
            self._stop(f'only {free / 1e6:.1f} MB left on the disk holding {self.path} '
                       f'(min_free_space {self._min_free_space / 1e6:.1f} MB)')
            return False
        try:
            self._writer.write(self._connections[topic], timestamp, data)
        except OSError as error:
            self._stop(f'writing {self.path} failed: {error}')
            return False
        return True

    def _stop(self, reason: str) -> None:
        self.stopped = reason
        try:
            self.close()
        except OSError as error:
            self.stopped += (f'; closing failed too ({error}): the .mcap has no index, '
                             '`mcap recover` reads it')

    def close(self) -> list[TopicRecord]:
        """
        Write the index and metadata.yaml; return what each topic holds.

        Safe to call twice.

        Raises
        ------
        OSError
            The index could not be written (the disk is full): the .mcap is readable only
            by a reader that scans it (``mcap recover``).

        """
        writer, self._writer = self._writer, None
        if writer is None:
            return self.records
        counts = dict(writer.counts)
        self.records = [TopicRecord(c.topic, c.msgtype, counts[c.id])
                        for c in writer.connections]
        try:
            writer.close()
        except OSError:
            writer.abort()
            raise
        return self.records


def _statvfs_free(path: Path) -> int:
    stat = os.statvfs(path)
    return stat.f_bavail * stat.f_frsize
