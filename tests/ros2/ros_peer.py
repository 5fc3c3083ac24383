#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""An independent ROS 2-style DDS participant for the bridge tests (Python cyclonedds,
types from ros_std_msgs.py). One job per run; results as JSON lines on stdout.

  ros_peer.py discover TOPIC=TYPE[:pub|:sub] ...   every topic's endpoint is seen with
        the DDS type name std_msgs::msg::dds_::TYPE_ and USER_DATA typehash=<RIHS01>;
  ros_peer.py echo TOPIC TYPE --count N            take samples (value, source timestamp,
        arrival) until N arrived or --timeout; --deadline-ms D also records deadline misses
  ros_peer.py deadline TOPIC MS                     a writer of TOPIC offers a deadline of MS
  ros_peer.py pub TOPIC TYPE VALUES_JSON           publish each value once a bridge reader
        matched (reliable), then linger so all are delivered
"""
import argparse
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "src", "ros2"))

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication, BuiltinTopicDcpsSubscription  # noqa: E402,E501
from cyclonedds.core import Listener, Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402

import ros_std_msgs as msgs  # noqa: E402
import type_hash  # noqa: E402  (the hashes the bridge is expected to announce)


def emit(**kw):
    print(json.dumps(kw), flush=True)


def qos_for(event, deadline_ms=None, reliable=True):
    pol = [Policy.Reliability.Reliable(duration(milliseconds=100)) if reliable else Policy.Reliability.BestEffort,
           Policy.History.KeepAll if event else Policy.History.KeepLast(10),
           Policy.Durability.Volatile,
           # XCDR1 only: a writer offering only XCDR2 would not match (ROS 2 uses XCDR1).
           Policy.DataRepresentation(use_cdrv0_representation=True)]
    if deadline_ms:
        pol.append(Policy.Deadline(duration(milliseconds=deadline_ms)))
    return Qos(*pol)


def cmd_discover(args, dp):
    want = {}
    for spec in args.topics:
        topic, _, rest = spec.partition("=")
        typ, _, side = rest.partition(":")
        want[topic] = (typ, side or "pub")
    hashes = type_hash.all_hashes()
    readers = {"pub": BuiltinDataReader(dp, BuiltinTopicDcpsPublication),
               "sub": BuiltinDataReader(dp, BuiltinTopicDcpsSubscription)}
    found, end = {}, time.time() + args.timeout
    while len(found) < len(want) and time.time() < end:
        for side, rd in readers.items():
            for ep in rd.take(N=64):
                w = want.get(ep.topic_name)
                if not w or w[1] != side or ep.topic_name in found:
                    continue
                ud = ep.qos[Policy.Userdata].data if Policy.Userdata in ep.qos else b""
                ros_name = "std_msgs/msg/" + w[0]
                found[ep.topic_name] = dict(topic=ep.topic_name, side=side, type_name=ep.type_name,
                                            user_data=ud.decode(errors="replace"),
                                            type_ok=ep.type_name == "std_msgs::msg::dds_::%s_" % w[0],
                                            hash_ok=ud == ("typehash=%s;" % hashes[ros_name]).encode())
        time.sleep(0.05)
    ok = len(found) == len(want) and all(f["type_ok"] and f["hash_ok"] for f in found.values())
    for f in found.values():
        emit(**f)
    for topic in set(want) - set(found):
        emit(topic=topic, missing=True)
    return 0 if ok else 1


class _Matched(Listener):
    def __init__(self):
        super().__init__()
        self.matched = threading.Event()
        self.deadline_misses = []

    def on_subscription_matched(self, reader, status):
        if status.current_count > 0:
            self.matched.set()

    def on_publication_matched(self, writer, status):
        if status.current_count > 0:
            self.matched.set()

    def on_requested_deadline_missed(self, reader, status):
        self.deadline_misses.append((time.time_ns(), status.total_count))


def cmd_echo(args, dp):
    cls = msgs.TYPES[args.type]
    lis = _Matched()
    rd = DataReader(dp, Topic(dp, args.topic, cls), qos=qos_for(args.event, args.deadline_ms), listener=lis)
    if not lis.matched.wait(args.match_timeout):
        emit(error="no writer matched %s within %.1f s" % (args.topic, args.match_timeout))
        return 1
    time.sleep(0.5)  # we matched the writer; give the writer's side time to match us too
    if args.ready:
        open(args.ready, "w").close()
    got, end = 0, time.time() + args.timeout
    out = open(args.out, "w") if args.out else sys.stdout
    while got < args.count and time.time() < end:
        for s in rd.take(N=256):
            info = s.sample_info
            if not info.valid_data:
                continue
            data = list(s.data_) if hasattr(s.data_, "__len__") else s.data_
            out.write(json.dumps(dict(data=data, src_ts=info.source_timestamp, rx=time.time_ns())) + "\n")
            got += 1
        time.sleep(0.0005)
    if args.linger:  # keep listening (deadline misses) without taking more
        time.sleep(max(0.0, end - time.time()) if args.count == 0 else args.linger)
    out.flush()
    emit(received=got, deadline_misses=[t for t, _ in lis.deadline_misses],
         mono_minus_wall=time.monotonic_ns() - time.time_ns())
    return 0 if got >= args.count else 1


def cmd_pub(args, dp):
    cls = msgs.TYPES[args.type]
    lis = _Matched()
    wr = DataWriter(dp, Topic(dp, args.topic, cls), qos=qos_for(args.event), listener=lis)
    if not lis.matched.wait(args.match_timeout):
        emit(error="no reader matched %s within %.1f s" % (args.topic, args.match_timeout))
        return 1
    time.sleep(0.5)  # our side matched; give the reader's side time to match us too
    values = json.loads(args.values)
    for v in values:
        wr.write(msgs.make(args.type, v) if not isinstance(v, dict) else msgs.make(args.type, v["data"], v.get("count"), v.get("dims")))
        if args.interval:
            time.sleep(args.interval)
    time.sleep(args.linger)
    emit(published=len(values))
    return 0


def cmd_deadline(args, dp):
    """The deadline (ms) offered by the writers of one topic, as DDS discovery tells them."""
    rd = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
    end, seen = time.time() + args.timeout, None
    while seen is None and time.time() < end:
        for ep in rd.take(N=64):
            if ep.topic_name == args.topic:
                dl = ep.qos[Policy.Deadline].deadline if Policy.Deadline in ep.qos else None
                seen = None if dl is None else dl / 1e6
        time.sleep(0.05)
    emit(topic=args.topic, deadline_ms=seen)
    return 0 if seen is not None and abs(seen - args.expect_ms) < 0.5 else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--domain", type=int, default=int(os.environ.get("ROS_DOMAIN_ID", "0")))
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("discover")
    d.add_argument("topics", nargs="+")
    d.add_argument("--timeout", type=float, default=10)
    dl = sub.add_parser("deadline")
    dl.add_argument("topic")
    dl.add_argument("expect_ms", type=float)
    dl.add_argument("--timeout", type=float, default=10)
    for name in ("echo", "pub"):
        p = sub.add_parser(name)
        p.add_argument("topic")
        p.add_argument("type", choices=sorted(msgs.TYPES))
        p.add_argument("--event", action="store_true", help="keep-all history (events)")
        p.add_argument("--match-timeout", type=float, default=10)
        if name == "echo":
            p.add_argument("--count", type=int, default=1)
            p.add_argument("--timeout", type=float, default=10)
            p.add_argument("--deadline-ms", type=int)
            p.add_argument("--ready", help="file created once a writer matched")
            p.add_argument("--out", help="samples as JSON lines to this file")
            p.add_argument("--linger", type=float, default=0)
        else:
            p.add_argument("values", help="JSON list of values (scalars, lists or {data, count})")
            p.add_argument("--interval", type=float, default=0)
            p.add_argument("--linger", type=float, default=1.0)
    args = ap.parse_args()
    dp = DomainParticipant(args.domain)
    return {"discover": cmd_discover, "echo": cmd_echo, "pub": cmd_pub, "deadline": cmd_deadline}[args.cmd](args, dp)


if __name__ == "__main__":
    sys.exit(main())
