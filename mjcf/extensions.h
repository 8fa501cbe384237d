/* What artic's compiled extensions share: the sealed parameter block and what their
 * loader (mjcf/extensions.py) checks.
 *
 * A compiled passive callback (plant/_tyre_c.c, the synthetic truth's in
 * validation/synthetic/_truth_c.c) reads its parameters from a model's numeric 0,
 * a block that starts with the callback's ABI and the process's key and carries a
 * checksum of what follows its header. The callback follows a block only when it
 * is sealed with this process's key and its checksum matches: a foreign or damaged
 * block is never followed. Each extension keeps its own copy of the key, which its
 * loader sets once (<prefix>_set_key).
 *
 * Checking a block in full costs about 5 % of a plant step, at each of RK4's four
 * stages, so each thread remembers the last block it found valid and the model
 * sizes it was checked against (seen_block): a block equal to it, bit for bit, in
 * a model of the same sizes, is valid without the checksum and the id scan. Any
 * edit of the block, in place or not, misses and is checked in full.
 *
 * Only the mechanics of the block are here; what a block means (tyres, steering)
 * stays in each extension.
 */
#ifndef ARTIC_EXTENSIONS_H
#define ARTIC_EXTENSIONS_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include <mujoco/mujoco.h>

/* This extension's copy of the process's key; 0, 0 until its loader sets it. */
static uint32_t key_hi = 0, key_lo = 0;

/* Set the process's key once; later calls keep the first. */
static inline void block_set_key(uint32_t hi, uint32_t lo) {
  if (key_hi == 0 && key_lo == 0) {
    key_hi = hi;
    key_lo = lo;
  }
}

/* A weighted sum of the block after the header, sealing it against damage. */
static inline double block_checksum(const double* body, int n) {
  double s = 0.0;
  int w = 1; /* (i % 97) + 1, without a division per value */
  for (int i = 0; i < n; i++) {
    s += body[i] * (double)w;
    if (++w > 97) w = 1;
  }
  return s;
}

/* Whether blk starts with abi and this process's key (abi, key_hi, key_lo). */
static inline int block_sealed(const double* blk, int abi) {
  return blk[0] == (double)abi && !(key_hi == 0 && key_lo == 0) && blk[1] == (double)key_hi
         && blk[2] == (double)key_lo;
}

/* m's numeric 0 when it is named name, and its size; NULL otherwise. */
static inline const double* block_of(const mjModel* m, const char* name, int* size) {
  if (m->nnumeric < 1 || strcmp(m->names + m->name_numericadr[0], name) != 0) return NULL;
  *size = m->numeric_size[0];
  return m->numeric_data + m->numeric_adr[0];
}

/* Whether x is an id in [0, n). */
static inline int id_ok(double x, int n) { return x >= 0.0 && x < n && x == floor(x); }

/* The last block a thread found valid: each extension declares its own,
 * static __thread seen_block seen; */
#define SEEN_MAX 4096 /* doubles; larger blocks are checked at every call */
#define N_SIZES 7
typedef struct {
  int size, n, sizes[N_SIZES]; /* n: what the extension keeps with it (its wheel count) */
  double blk[SEEN_MAX];
} seen_block;

/* The model sizes the ids of a block are checked against. */
static inline void model_sizes(const mjModel* m, int out[N_SIZES]) {
  out[0] = m->nsite;
  out[1] = m->nbody;
  out[2] = m->nv;
  out[3] = m->na;
  out[4] = m->nu;
  out[5] = m->nuserdata;
  out[6] = m->nq;
}

/* Whether blk (of size entries) in m is the block s remembers; its n then in *n. */
static inline int seen_before(const seen_block* s, const mjModel* m, const double* blk, int size,
                              int* n) {
  int sizes[N_SIZES];
  model_sizes(m, sizes);
  if (size == s->size && memcmp(sizes, s->sizes, sizeof sizes) == 0
      && memcmp(blk, s->blk, (size_t)size * sizeof(double)) == 0) {
    *n = s->n;
    return 1;
  }
  return 0;
}

/* Remember blk, found valid in m, with n. */
static inline void remember(seen_block* s, const mjModel* m, const double* blk, int size, int n) {
  if (size > SEEN_MAX) return;
  s->size = 0; /* invalid while it is written */
  memcpy(s->blk, blk, (size_t)size * sizeof(double));
  model_sizes(m, s->sizes);
  s->n = n;
  s->size = size;
}

/* The functions the loader calls (mjcf/extensions.py), named <prefix>_...:
 * the ABI, the MuJoCo version compiled against, the key's setter and the
 * checksum (for Python's seal). */
#define ARTIC_EXPORTS(prefix, abi)                                                             \
  int prefix##_abi(void) { return (abi); }                                                     \
  int prefix##_mj_version(void) { return mjVERSION_HEADER; }                                   \
  void prefix##_set_key(uint32_t hi, uint32_t lo) { block_set_key(hi, lo); }                   \
  double prefix##_checksum(const double* body, int n) { return block_checksum(body, n); }

#endif
