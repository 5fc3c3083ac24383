/* SPDX-License-Identifier: Apache-2.0 */
/*
 * A client gone wrong: maps a node's shared-memory segment read-write as any member of
 * the ccomm group can (plain mmap of /dev/shm, no libccomm) and writes random bytes
 * over it.
 *
 *   garbage SHM_NAME data|all SECONDS [SEED]
 *
 * data: every byte of the signals' data area (state cells, event rings, slots), first
 *       in one pass, then random runs of 1..64 bytes at random places until SECONDS.
 * all:  the same over the whole segment: header, directory, counters, everything.
 * Prints one JSON line with what it wrote. Exit 0, or 2 on a usage/OS error.
 */
#include <fcntl.h>
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static uint64_t rng_state;
static uint64_t next_random(void) { /* xorshift64* */
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return rng_state * 0x2545F4914F6CDD1Dull;
}

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

static uint64_t load64(const uint8_t* p) {
  uint64_t v;
  memcpy(&v, p, 8);
  return v;
}

int main(int argc, char** argv) {
  if (argc < 4) {
    fprintf(stderr, "usage: garbage SHM_NAME data|all SECONDS [SEED]\n");
    return 2;
  }
  const int all = strcmp(argv[2], "all") == 0;
  const double seconds = atof(argv[3]);
  rng_state = argc > 4 ? strtoull(argv[4], NULL, 0) : (uint64_t)time(NULL);
  if (!rng_state) rng_state = 1;
  int fd = shm_open(argv[1], O_RDWR, 0);
  if (fd < 0) { perror("garbage: shm_open"); return 2; }
  struct stat st;
  if (fstat(fd, &st) != 0) { perror("garbage: fstat"); return 2; }
  const size_t size = (size_t)st.st_size;
  uint8_t* base = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (base == MAP_FAILED) { perror("garbage: mmap"); return 2; }
  close(fd);
  /* Where the data area starts (store/layout.h, SegmentHeader): after the dirty map. */
  const uint32_t signals = (uint32_t)load64(base + 24);
  const uint64_t dirty = load64(base + 64);
  size_t start = all ? 0 : (size_t)((dirty + ((signals + 63) / 64) * 8 + 63) & ~(uint64_t)63);
  if (start >= size) { fprintf(stderr, "garbage: data area outside the segment\n"); return 2; }
  uint64_t bytes = 0, runs = 0;
  for (size_t i = start; i < size; i += 8) { /* one full pass */
    uint64_t r = next_random();
    memcpy(base + i, &r, size - i < 8 ? size - i : 8);
  }
  bytes += size - start;
  const double end = now_s() + seconds;
  while (now_s() < end) {
    for (int k = 0; k < 1000; ++k) {
      size_t len = 1 + next_random() % 64;
      size_t at = start + next_random() % (size - start);
      if (at + len > size) len = size - at;
      for (size_t j = 0; j < len; ++j) base[at + j] = (uint8_t)next_random();
      bytes += len;
      runs++;
    }
    usleep(1000);
  }
  printf("{\"garbage\":\"%s\",\"mode\":\"%s\",\"segment_bytes\":%zu,\"from\":%zu,\"bytes_written\":%" PRIu64
         ",\"runs\":%" PRIu64 "}\n", argv[1], all ? "all" : "data", size, start, bytes, runs);
  return 0;
}
