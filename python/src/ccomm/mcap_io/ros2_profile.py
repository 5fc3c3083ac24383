# SPDX-License-Identifier: Apache-2.0
"""The "ros2" recording profile: what ROS 2 tools (rosbag2's MCAP storage, `ros2 bag
play`, mcap-ros2-support, rosbags, Foxglove) read.

MCAP profile "ros2", one channel per signal on the topic /NAMESPACE/SIGNAL (the ROS 2
name ccomm-ros2 publishes it under), schema encoding "ros2msg" with the std_msgs
definition, message encoding "cdr" (XCDR1 little-endian, as ROS 2 serializes). The
types are the bridge's (docs/integrations/ros2.md, src/ros2/dds_types.cpp):

    double float int32 uint32 int64 bool     -> std_msgs/msg/Float64 Float32 Int32 UInt32 Int64 Bool
    the same with count > 1                  -> std_msgs/msg/*MultiArray (bool: UInt8MultiArray 0/1)

An array has layout.dim = [{label: SIGNAL, size: n, stride: n}], data_offset 0. What
std_msgs has no field for is kept in the MCAP record: log time = receive time, publish
time = source time (both Unix time, as in the json profile), sequence = the low 32 bits
of seq. Freshness, loss and gaps are not in these messages: record with the default
profile when those matter (and for ccomm-replay, which reads that one).

Each channel carries `offered_qos_profiles` (the profile's one required channel
metadata; `ros2 bag play` offers the QoS it names): a YAML list of one profile, the QoS
ccomm-ros2's writer offers for the signal (docs/integrations/ros2.md, QoS): reliable,
volatile, a state keep-last 1 with a deadline of stale_after_ms (none: infinite), an
event keep-all. Written in rosbag2's integer form (the rmw enum values, bag format 8 and
before), which every rosbag2 reads (later ones detect it)."""
from __future__ import annotations

import struct
from typing import Tuple

from ..client import SignalInfo, SignalType
from .schema import MessageEncoder

PROFILE = "ros2"
SCHEMA_ENCODING = "ros2msg"
MESSAGE_ENCODING = "cdr"
DEFAULT_NAMESPACE = "ccomm"
_CDR_LE = b"\x00\x01\x00\x00"  # encapsulation: plain CDR, little-endian

# ccomm type -> (scalar message, array message, ROS 2 primitive, element size)
_TYPES = {
    SignalType.DOUBLE: ("Float64", "Float64MultiArray", "float64", 8),
    SignalType.FLOAT: ("Float32", "Float32MultiArray", "float32", 4),
    SignalType.INT32: ("Int32", "Int32MultiArray", "int32", 4),
    SignalType.UINT32: ("UInt32", "UInt32MultiArray", "uint32", 4),
    SignalType.INT64: ("Int64", "Int64MultiArray", "int64", 8),
    SignalType.BOOL: ("Bool", "UInt8MultiArray", "bool", 1),
}
_SEPARATOR = "=" * 80 + "\n"
_LAYOUT = ("MSG: std_msgs/MultiArrayLayout\n"
           "MultiArrayDimension[] dim\n"
           "uint32 data_offset\n")
_DIMENSION = ("MSG: std_msgs/MultiArrayDimension\n"
              "string label\n"
              "uint32 size\n"
              "uint32 stride\n")


def ros_type(desc: SignalInfo) -> str:
    """The std_msgs type of a signal, as ROS 2 names it ("std_msgs/msg/Float64")."""
    scalar, array, _, _ = _TYPES[desc.type]
    return "std_msgs/msg/" + (array if desc.count > 1 else scalar)


def topic(desc: SignalInfo, namespace: str = DEFAULT_NAMESPACE) -> str:
    return "/" + (namespace + "/" if namespace else "") + desc.name


def definition(desc: SignalInfo) -> bytes:
    """The message definition in rosbag2's concatenated .msg form."""
    _, _, primitive, _ = _TYPES[desc.type]
    if desc.count == 1:
        return (primitive + " data\n").encode()
    element = "uint8" if desc.type == SignalType.BOOL else primitive
    return ("MultiArrayLayout layout\n" + element + "[] data\n" +
            _SEPARATOR + _LAYOUT + _SEPARATOR + _DIMENSION).encode()


# rmw's enum values (rmw/types.h) and its infinite duration, as rosbag2 writes them
_KEEP_LAST, _KEEP_ALL = 1, 2
_RELIABLE = 1
_VOLATILE = 2
_AUTOMATIC = 1
_INFINITE = (9223372036, 854775807)  # RMW_DURATION_INFINITE: (sec, nsec)


def offered_qos_profiles(desc: SignalInfo) -> str:
    """The channel's offered_qos_profiles: the QoS ccomm-ros2's writer of the signal offers,
    as rosbag2 serializes a list of profiles (YAML, its key order, no final newline)."""
    history, depth = (_KEEP_ALL, 0) if desc.is_event else (_KEEP_LAST, 1)
    ms = desc.stale_after_ms if not desc.is_event else 0
    deadline = divmod(ms * 1_000_000, 1_000_000_000) if ms > 0 else _INFINITE

    def duration(key: str, d: Tuple[int, int]) -> str:
        return f"  {key}:\n    sec: {d[0]}\n    nsec: {d[1]}\n"

    return (f"- history: {history}\n  depth: {depth}\n  reliability: {_RELIABLE}\n  durability: {_VOLATILE}\n" +
            duration("deadline", deadline) + duration("lifespan", _INFINITE) +
            f"  liveliness: {_AUTOMATIC}\n" + duration("liveliness_lease_duration", _INFINITE) +
            "  avoid_ros_namespace_conventions: false")


def _align(n: int, a: int) -> int:
    return (n + a - 1) // a * a


def message_encoder(desc: SignalInfo) -> Tuple[None, MessageEncoder]:
    """(None, encode) with the json profile's encoder signature: the CDR message of one
    value. The value bytes ccomm stores are already the little-endian elements CDR wants,
    so a message is a constant prefix and the value's bytes."""
    _, _, _, size = _TYPES[desc.type]
    n = desc.value_bytes
    if desc.count == 1:
        prefix = _CDR_LE
    else:
        label = desc.name.encode() + b"\x00"
        body = struct.pack("<I", 1) + struct.pack("<I", len(label)) + label
        body += b"\x00" * (_align(len(body), 4) - len(body))
        body += struct.pack("<III", desc.count, desc.count, 0)  # size, stride, data_offset
        body += struct.pack("<I", desc.count)
        body += b"\x00" * (_align(len(body), size) - len(body))
        prefix = _CDR_LE + body

    def encode(buf: bytes, off: int, status: int, flags: int, seq: int, recv: int, src: int, lost: int,
               gap: int, prod: int, prod_err: int, code: int) -> bytes:  # times: the publish time
        return prefix + bytes(buf[off:off + n])

    return None, encode


def schema_and_channel(desc: SignalInfo, namespace: str = DEFAULT_NAMESPACE) -> Tuple[str, bytes, str]:
    """(schema name, schema data, topic) of one signal's channel."""
    return ros_type(desc), definition(desc), topic(desc, namespace)
