// SPDX-License-Identifier: Apache-2.0
// The system view object (view.h): creation, read-only mapping, per-node seqlock.
#include "store/view.h"

#include <errno.h>
#include <string.h>


#include "common/platform.h"
#include "store/word_copy.h"  // the seqlock fences (and their TSan form)

namespace ccomm {
namespace store {
namespace {

constexpr size_t kAlign = 64;
inline size_t Up(size_t v) { return (v + kAlign - 1) & ~(kAlign - 1); }
inline size_t NodesOffset() { return Up(sizeof(ViewHeader)); }
inline size_t RowsOffset(uint32_t nodes) { return Up(NodesOffset() + size_t{nodes} * sizeof(ViewNode)); }
constexpr int kReadTries = 64;  // a write is a few dozen stores: this many retries is ample

}  // namespace

std::string View::NameFor(const std::string& node) { return platform::SegmentName(node) + ".view"; }

size_t View::SizeFor(uint32_t nodes, uint32_t signals) {
  return RowsOffset(nodes) + size_t{nodes} * signals * sizeof(ViewRow);
}

int View::Create(const std::string& name, uint32_t nodes, uint32_t signals, uint32_t self, uint32_t summary_ms,
                 int gid, std::string* error) {
  Close();
  platform::ShmUnlink(name.c_str());  // a previous ccommd's: its readers keep their copy
  const size_t size = SizeFor(nodes, signals);
  int fd = platform::ShmOpen(name.c_str(), true, 0660);
  if (fd < 0) {
    *error = "cannot create shared memory " + name + ": " + strerror(-fd);
    if (fd == -EEXIST || fd == -EACCES || fd == -EPERM)
      *error += " (left by a ccommd of another user? remove /dev/shm" + name + ")";
    return fd;
  }
  if (gid >= 0 && platform::ShmSetGroup(fd, gid) != 0) {
    // Not fatal: members of the group just cannot read the view.
  }
  int r = platform::Truncate(fd, size);
  void* p = r == 0 ? platform::MapShared(fd, size) : nullptr;
  if (p == nullptr) {
    r = r ? r : -errno;
    platform::CloseFd(fd);
    platform::ShmUnlink(name.c_str());
    *error = "cannot size/map shared memory " + name + ": " + strerror(-r);
    return r;
  }
  platform::CloseFd(fd);
  base_ = p;
  size_ = size;
  created_name_ = name;
  // ftruncate zeroed it: every counter and word starts at 0, every seq even.
  ViewHeader* h = mutable_header();
  h->magic = kViewMagic;
  h->version = kViewVersion;
  h->node_count = nodes;
  h->signal_count = signals;
  h->self = self;
  h->summary_ms = summary_ms;
  h->size = size;
  h->state.store(kViewReady, std::memory_order_release);
  return 0;
}

int View::OpenReadOnly(const std::string& name) {
  Close();
  int fd = platform::ShmOpenReadOnly(name.c_str());
  if (fd < 0) return fd;
  size_t size = 0;
  int r = platform::FileSize(fd, &size);
  if (r == 0 && size < sizeof(ViewHeader)) r = -EPROTO;
  const void* p = nullptr;
  if (r == 0) {
    p = platform::MapSharedReadOnly(fd, size);
    if (!p) r = -errno;
  }
  platform::CloseFd(fd);
  if (r != 0) return r;
  const ViewHeader* h = static_cast<const ViewHeader*>(p);
  if (h->state.load(std::memory_order_acquire) != kViewReady || h->magic != kViewMagic ||
      h->version != kViewVersion || h->size != size || SizeFor(h->node_count, h->signal_count) != size ||
      h->self >= h->node_count) {
    platform::Unmap(const_cast<void*>(p), size);
    return -EPROTO;
  }
  base_ = const_cast<void*>(p);
  size_ = size;
  return 0;
}

void View::Remove() {
  if (created_name_.empty()) return;
  platform::ShmUnlink(created_name_.c_str());
  created_name_.clear();
}

void View::Close() {
  platform::Unmap(base_, size_);
  base_ = nullptr;
  size_ = 0;
}

ViewNode* View::Node(uint32_t n) const {
  return reinterpret_cast<ViewNode*>(static_cast<char*>(base_) + NodesOffset()) + n;
}

ViewRow* View::Row(uint32_t n, uint32_t s) const {
  return reinterpret_cast<ViewRow*>(static_cast<char*>(base_) + RowsOffset(header()->node_count)) +
         size_t{n} * header()->signal_count + s;
}

void View::BeginWrite(uint32_t node) {
  ViewNode* v = Node(node);
  v->seq.store(v->seq.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  SeqlockWriterFence();  // odd seq before any data store
}

void View::SetNodeWord(uint32_t node, ViewNodeWord w, uint64_t v) { Node(node)->w[w].store(v, kMetaStore); }

void View::SetRow(uint32_t node, uint32_t signal, uint8_t role, uint8_t flags, uint32_t rate_mhz, uint64_t lost,
                  uint32_t age_ms, uint64_t rx_ns) {
  ViewRow* r = Row(node, signal);
  r->w[0].store(1u | uint64_t{role} << 8 | uint64_t{flags} << 16 | uint64_t{rate_mhz} << 32, kMetaStore);
  r->w[1].store(lost, kMetaStore);
  r->w[2].store(age_ms, kMetaStore);
  r->w[3].store(rx_ns, kMetaStore);
}

void View::EndWrite(uint32_t node) {
  ViewNode* v = Node(node);
  v->seq.store(v->seq.load(std::memory_order_relaxed) + 1, std::memory_order_release);
}

bool View::ReadNode(uint32_t node, ViewNodeCopy* out) const {
  if (!base_ || node >= header()->node_count) return false;
  const ViewNode* v = Node(node);
  for (int i = 0; i < kReadTries; ++i) {
    const uint32_t s1 = v->seq.load(std::memory_order_acquire);
    if (s1 & 1u) continue;
    for (uint32_t k = 0; k < kVwNodeWords; ++k) out->w[k] = v->w[k].load(kMetaLoad);
    SeqlockReaderFence();
    if (v->seq.load(std::memory_order_relaxed) == s1) return true;
  }
  return false;
}

bool View::ReadRow(uint32_t node, uint32_t signal, ViewRowCopy* out) const {
  if (!base_ || node >= header()->node_count || signal >= header()->signal_count) return false;
  const ViewNode* v = Node(node);
  const ViewRow* r = Row(node, signal);
  for (int i = 0; i < kReadTries; ++i) {
    const uint32_t s1 = v->seq.load(std::memory_order_acquire);
    if (s1 & 1u) continue;
    const uint64_t w0 = r->w[0].load(kMetaLoad);
    out->lost = r->w[1].load(kMetaLoad);
    out->age_ms = static_cast<uint32_t>(r->w[2].load(kMetaLoad));
    out->rx_ns = r->w[3].load(kMetaLoad);
    SeqlockReaderFence();
    if (v->seq.load(std::memory_order_relaxed) != s1) continue;
    out->present = (w0 & 1u) != 0;
    out->role = static_cast<uint8_t>(w0 >> 8);
    out->flags = static_cast<uint8_t>(w0 >> 16);
    out->rate_mhz = static_cast<uint32_t>(w0 >> 32);
    return true;
  }
  return false;
}

}  // namespace store
}  // namespace ccomm
