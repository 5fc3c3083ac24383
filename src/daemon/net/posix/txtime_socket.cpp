// SPDX-License-Identifier: Apache-2.0
// Launch times on Linux sockets (txtime_socket.h): SO_TXTIME, the qdisc probe over
// rtnetlink, sendmsg with SCM_TXTIME, the error queue's ETF drop reports.
#include "daemon/net/posix/txtime_socket.h"

#include <errno.h>
#include <linux/errqueue.h>
#include <linux/net_tstamp.h>
#include <linux/netlink.h>
#include <linux/pkt_sched.h>
#include <linux/rtnetlink.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <vector>

namespace ccomm {
namespace {

struct Qdisc {
  std::string kind;
  uint32_t handle = 0, parent = 0;
  std::vector<uint8_t> options;  // TCA_OPTIONS payload
};

// The TCA_ETF_PARMS of an etf qdisc's options, if on CLOCK_TAI.
bool EtfParams(const Qdisc& q, uint64_t* delta_ns) {
  if (q.kind != "etf") return false;
  const uint8_t* p = q.options.data();
  size_t left = q.options.size();
  while (left >= sizeof(nlattr)) {
    nlattr a;
    memcpy(&a, p, sizeof a);
    if (a.nla_len < sizeof a || a.nla_len > left) return false;
    if ((a.nla_type & NLA_TYPE_MASK) == TCA_ETF_PARMS && a.nla_len >= NLA_HDRLEN + sizeof(tc_etf_qopt)) {
      tc_etf_qopt o;
      memcpy(&o, p + NLA_HDRLEN, sizeof o);
      if (o.clockid != CLOCK_TAI) return false;
      *delta_ns = o.delta > 0 ? static_cast<uint64_t>(o.delta) : 0;
      return true;
    }
    const size_t step = NLA_ALIGN(a.nla_len);
    if (step >= left) break;
    p += step;
    left -= step;
  }
  return false;
}

const Qdisc* ChildAt(const std::vector<Qdisc>& all, uint32_t parent) {
  for (const Qdisc& q : all)
    if (q.parent == parent) return &q;
  return nullptr;
}

bool DumpQdiscs(int ifindex, std::vector<Qdisc>* out, std::string* err) {
  const int fd = socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
  if (fd < 0) {
    *err = std::string("netlink: ") + strerror(errno);
    return false;
  }
  struct {
    nlmsghdr h;
    tcmsg t;
  } req;
  memset(&req, 0, sizeof req);
  req.h.nlmsg_len = sizeof req;
  req.h.nlmsg_type = RTM_GETQDISC;
  req.h.nlmsg_flags = NLM_F_REQUEST | NLM_F_DUMP;
  req.h.nlmsg_seq = 1;
  req.t.tcm_family = AF_UNSPEC;
  req.t.tcm_ifindex = ifindex;
  if (send(fd, &req, sizeof req, 0) < 0) {
    *err = std::string("netlink: ") + strerror(errno);
    close(fd);
    return false;
  }
  std::vector<uint8_t> buf(65536);
  bool done = false;
  for (int rounds = 0; rounds < 256 && !done; ++rounds) {  // bounded: a dump of one host's qdiscs
    const ssize_t n = recv(fd, buf.data(), buf.size(), 0);
    if (n <= 0) break;
    size_t len = static_cast<size_t>(n);
    for (const nlmsghdr* h = reinterpret_cast<const nlmsghdr*>(buf.data()); NLMSG_OK(h, len); h = NLMSG_NEXT(h, len)) {
      if (h->nlmsg_type == NLMSG_DONE || h->nlmsg_type == NLMSG_ERROR) {
        done = true;
        break;
      }
      if (h->nlmsg_type != RTM_NEWQDISC) continue;
      const tcmsg* t = static_cast<const tcmsg*>(NLMSG_DATA(h));
      if (t->tcm_ifindex != ifindex) continue;
      Qdisc q;
      q.handle = t->tcm_handle;
      q.parent = t->tcm_parent;
      int alen = static_cast<int>(h->nlmsg_len) - static_cast<int>(NLMSG_LENGTH(sizeof *t));
      for (const rtattr* a = reinterpret_cast<const rtattr*>(reinterpret_cast<const uint8_t*>(t) + NLMSG_ALIGN(sizeof *t));
           RTA_OK(a, alen); a = RTA_NEXT(a, alen)) {
        const uint8_t* d = static_cast<const uint8_t*>(RTA_DATA(a));
        const size_t dl = RTA_PAYLOAD(a);
        if (a->rta_type == TCA_KIND) q.kind.assign(reinterpret_cast<const char*>(d), strnlen(reinterpret_cast<const char*>(d), dl));
        if (a->rta_type == TCA_OPTIONS) q.options.assign(d, d + dl);
      }
      out->push_back(std::move(q));
    }
  }
  close(fd);
  return true;
}

}  // namespace

int EnableTxtime(int fd) {
  sock_txtime cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.clockid = CLOCK_TAI;
  cfg.flags = SOF_TXTIME_REPORT_ERRORS;
  if (setsockopt(fd, SOL_SOCKET, SO_TXTIME, &cfg, sizeof cfg) != 0) return errno;
  int prio = kTxtimePriority;
  if (setsockopt(fd, SOL_SOCKET, SO_PRIORITY, &prio, sizeof prio) != 0) return errno;
  return 0;
}

void ProbeEtf(int ifindex, TxtimeProbe* p, std::string* detail) {
  std::vector<Qdisc> all;
  std::string err;
  if (!DumpQdiscs(ifindex, &all, &err)) {
    *detail = "cannot read the qdiscs: " + err;
    return;
  }
  const Qdisc* root = ChildAt(all, TC_H_ROOT);
  if (!root) {
    *detail = "no root qdisc";
    return;
  }
  const uint32_t major = root->handle & TC_H_MAJ_MASK;
  auto hex = [](uint32_t h) {
    char b[16];
    snprintf(b, sizeof b, "%x:", h >> 16);
    return std::string(b);
  };
  if (root->kind == "etf") {
    p->etf = EtfParams(*root, &p->etf_delta_ns);
    *detail = p->etf ? "root etf" : "root etf not on CLOCK_TAI";
  } else if (root->kind == "prio" && root->options.size() >= sizeof(tc_prio_qopt)) {
    tc_prio_qopt o;
    memcpy(&o, root->options.data(), sizeof o);
    const unsigned band = o.priomap[kTxtimePriority];
    const Qdisc* child = ChildAt(all, major | (band + 1));
    p->etf = child && EtfParams(*child, &p->etf_delta_ns);
    *detail = "root prio " + hex(major) + ", priority " + std::to_string(kTxtimePriority) + " -> class " + hex(major) +
              std::to_string(band + 1) + ": " + (child ? child->kind : std::string("no qdisc")) +
              (child && child->kind == "etf" && !p->etf ? " (not on CLOCK_TAI)" : "");
  } else if (root->kind == "mqprio" && root->options.size() >= sizeof(tc_mqprio_qopt)) {
    tc_mqprio_qopt o;
    memcpy(&o, root->options.data(), sizeof o);
    const unsigned tc = o.prio_tc_map[kTxtimePriority];
    bool all_etf = tc < TC_QOPT_MAX_QUEUE && o.count[tc] > 0;
    for (unsigned q = 0; all_etf && q < o.count[tc]; ++q) {
      const Qdisc* child = ChildAt(all, major | (o.offset[tc] + q + 1u));
      uint64_t delta = 0;
      all_etf = child && EtfParams(*child, &delta);
      if (delta > p->etf_delta_ns) p->etf_delta_ns = delta;
    }
    p->etf = all_etf;
    *detail = "root mqprio " + hex(major) + ", priority " + std::to_string(kTxtimePriority) + " -> traffic class " +
              std::to_string(tc) + (all_etf ? ": etf on its queues" : ": not etf on every queue of it");
  } else {
    *detail = "root qdisc " + root->kind;
  }
  if (p->etf) *detail += ", etf delta " + std::to_string(p->etf_delta_ns / 1000) + " us";
}

uint64_t TaiNs() {
  timespec t;
  clock_gettime(CLOCK_TAI, &t);
  return static_cast<uint64_t>(t.tv_sec) * 1000000000ull + static_cast<uint64_t>(t.tv_nsec);
}

int64_t TaiMinusRealtimeNs() {
  timespec tai, real;
  clock_gettime(CLOCK_REALTIME, &real);
  clock_gettime(CLOCK_TAI, &tai);
  const int64_t d = (static_cast<int64_t>(tai.tv_sec) - real.tv_sec) * 1000000000 + (tai.tv_nsec - real.tv_nsec);
  return (d + 500000000) / 1000000000 * 1000000000;  // whole seconds: drop the time between the reads
}

int SendWithLaunch(int fd, const void* name, socklen_t namelen, const uint8_t* frame, size_t len,
                   uint64_t launch_tai_ns) {
  iovec iov = {const_cast<uint8_t*>(frame), len};
  alignas(cmsghdr) char ctl[CMSG_SPACE(sizeof(uint64_t))];
  memset(ctl, 0, sizeof ctl);
  msghdr m;
  memset(&m, 0, sizeof m);
  m.msg_name = const_cast<void*>(name);
  m.msg_namelen = namelen;
  m.msg_iov = &iov;
  m.msg_iovlen = 1;
  m.msg_control = ctl;
  m.msg_controllen = sizeof ctl;
  cmsghdr* c = CMSG_FIRSTHDR(&m);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SCM_TXTIME;
  c->cmsg_len = CMSG_LEN(sizeof(uint64_t));
  memcpy(CMSG_DATA(c), &launch_tai_ns, sizeof launch_tai_ns);
  const ssize_t n = sendmsg(fd, &m, 0);
  return n == static_cast<ssize_t>(len) ? 0 : -errno;
}

uint32_t DrainTxtimeErrors(int fd) {
  uint32_t drops = 0;
  for (int i = 0; i < 64; ++i) {
    uint8_t data[64];
    alignas(cmsghdr) char ctl[512];
    iovec iov = {data, sizeof data};
    msghdr m;
    memset(&m, 0, sizeof m);
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = ctl;
    m.msg_controllen = sizeof ctl;
    if (recvmsg(fd, &m, MSG_ERRQUEUE | MSG_DONTWAIT) < 0) break;
    for (cmsghdr* c = CMSG_FIRSTHDR(&m); c; c = CMSG_NXTHDR(&m, c)) {
      if (c->cmsg_len < CMSG_LEN(sizeof(sock_extended_err))) continue;
      sock_extended_err e;
      memcpy(&e, CMSG_DATA(c), sizeof e);
      if (e.ee_origin == SO_EE_ORIGIN_TXTIME) ++drops;
    }
  }
  return drops;
}

}  // namespace ccomm
