# SPDX-License-Identifier: Apache-2.0
"""ROS 2 std_msgs types as they are on DDS, for the independent test participant.

Written from ROS 2's std_msgs .msg definitions and rosidl_generator_dds_idl's naming
(module std_msgs::msg::dds_, type and member names with a trailing underscore), with the
Python cyclonedds IDL layer: none of this is the bridge's code.
"""
from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import final
from cyclonedds.idl import types as t

P = "std_msgs::msg::dds_::"


@final
@dataclass
class Float64_(IdlStruct, typename=P + "Float64_"):
    data_: t.float64


@final
@dataclass
class Float32_(IdlStruct, typename=P + "Float32_"):
    data_: t.float32


@final
@dataclass
class Int32_(IdlStruct, typename=P + "Int32_"):
    data_: t.int32


@final
@dataclass
class UInt32_(IdlStruct, typename=P + "UInt32_"):
    data_: t.uint32


@final
@dataclass
class Int64_(IdlStruct, typename=P + "Int64_"):
    data_: t.int64


@final
@dataclass
class Bool_(IdlStruct, typename=P + "Bool_"):
    data_: bool


@final
@dataclass
class MultiArrayDimension_(IdlStruct, typename=P + "MultiArrayDimension_"):
    label_: str
    size_: t.uint32
    stride_: t.uint32


@final
@dataclass
class MultiArrayLayout_(IdlStruct, typename=P + "MultiArrayLayout_"):
    dim_: t.sequence[MultiArrayDimension_]
    data_offset_: t.uint32


@final
@dataclass
class Float64MultiArray_(IdlStruct, typename=P + "Float64MultiArray_"):
    layout_: MultiArrayLayout_
    data_: t.sequence[t.float64]


@final
@dataclass
class Float32MultiArray_(IdlStruct, typename=P + "Float32MultiArray_"):
    layout_: MultiArrayLayout_
    data_: t.sequence[t.float32]


@final
@dataclass
class Int32MultiArray_(IdlStruct, typename=P + "Int32MultiArray_"):
    layout_: MultiArrayLayout_
    data_: t.sequence[t.int32]


@final
@dataclass
class UInt32MultiArray_(IdlStruct, typename=P + "UInt32MultiArray_"):
    layout_: MultiArrayLayout_
    data_: t.sequence[t.uint32]


@final
@dataclass
class Int64MultiArray_(IdlStruct, typename=P + "Int64MultiArray_"):
    layout_: MultiArrayLayout_
    data_: t.sequence[t.int64]


@final
@dataclass
class UInt8MultiArray_(IdlStruct, typename=P + "UInt8MultiArray_"):
    layout_: MultiArrayLayout_
    data_: t.sequence[t.uint8]


TYPES = {cls.__name__.rstrip("_"): cls for cls in (
    Float64_, Float32_, Int32_, UInt32_, Int64_, Bool_, Float64MultiArray_, Float32MultiArray_,
    Int32MultiArray_, UInt32MultiArray_, Int64MultiArray_, UInt8MultiArray_)}

# RIHS01 hashes as published in ROS 2's generated std_msgs (rosidl_generator_c
# *__description.c of a Jazzy/Kilted build): the reference the bridge's are checked against.
PUBLISHED_HASHES = {
    "std_msgs/msg/Float64": "RIHS01_705ba9c3d1a09df43737eb67095534de36fd426c0587779bda2bc51fe790182a",
    "std_msgs/msg/Bool": "RIHS01_feb91e995ff9ebd09c0cb3d2aed18b11077585839fb5db80193b62d74528f6c9",
    "std_msgs/msg/Float64MultiArray": "RIHS01_1025ddc6b9552d191f89ef1a8d2f60f3d373e28b283d8891ddcc974e8c55397f",
    "std_msgs/msg/MultiArrayLayout": "RIHS01_4c66e6f78e740ac103a94cf63259f968e48c617e7699e829b63c21a5cb50dac6",
    "std_msgs/msg/MultiArrayDimension": "RIHS01_5e773a60a4c7fc8a54985f307c7837aa2994252a126c301957a24e31282c9cbe",
}


def make(name, values, count=None, dims=None):
    """A sample of std_msgs type `name` ("Float64", "Int32MultiArray", ...); an array's
    layout is one dimension of `count` (default: the values) or `dims`, [[size, stride]...]."""
    cls = TYPES[name]
    if not name.endswith("MultiArray"):
        return cls(data_=values)
    values = list(values)
    n = len(values) if count is None else count
    dims = dims if dims is not None else [[n, n]]
    layout = MultiArrayLayout_(dim_=[MultiArrayDimension_(label_="", size_=size, stride_=stride)
                                     for size, stride in dims], data_offset_=0)
    return cls(layout_=layout, data_=values)
