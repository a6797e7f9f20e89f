/* cosmic-cyclone-cdr-peer: Eclipse Cyclone DDS (0.10, C API) serializing and deserializing the
 * types of cdr_check.idl in process, for the CDR cross-check against cosmic::CdrRepresentation
 * (cdr_check_test.sh; the other side is tests/peers/cdr_peer.cpp).
 *
 *   cosmic-cyclone-cdr-peer write   one line per sample on stdout:  K EXT VERSION ORDER HEX
 *   cosmic-cyclone-cdr-peer read    such lines on stdin: each deserialized by Cyclone and compared
 *                                   with sample K; one line per sample on stdout, "ok ..." or why not
 *
 * K is 0..2 (the values below; cdr_peer.cpp computes the same), EXT final or appendable (the
 * cdrcheck or cdrcheck_app module), VERSION xcdr1 or xcdr2, ORDER le or be, HEX the sample,
 * encapsulation header first. Cyclone refuses XCDR1 for an appendable type, so that pair is absent.
 *
 * Little-endian samples take Cyclone's own path: a writer and a reader of one participant with the
 * data representation set (local delivery, no network), dds_write, then dds_takecdr and
 * ddsi_serdata_to_ser: the serialized sample as it would go on the wire, header and padding as
 * Cyclone writes them. Cyclone writes in the host's order only, so big-endian samples are its
 * stream writer's (dds_stream_writeBE) body behind a header and padding made by the rule of its
 * serdata (ostream_add_to_serdata_default: padded to 4, the count in the options' last two bits).
 * Reading takes Cyclone's receive path: ddsi_serdata_from_ser_iov (which checks the sample with
 * dds_stream_normalize) and ddsi_serdata_to_sample, with the sertype of the matching writer.
 *
 * Exit 0: every sample written (write) or read back equal (read); 1: a sample differs or Cyclone
 * refused it; 2: bad arguments; 3: DDS entity creation failed.
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/dds.h"
#include "dds/ddsi/ddsi_cdrstream.h"
#include "dds/ddsi/ddsi_serdata.h"
#include "dds/ddsi/ddsi_sertype.h"

#include "cdr_check.h"

#define SAMPLES 3

static const char* const kNames[SAMPLES] = {"", "abc", "abcdefgh"};
static const char* const kLabels[SAMPLES][2] = {{"", "wxyz"}, {"a", "bc"}, {"hi", ""}};

/* Sample k, for either module's Sample (the same members): sequences on the heap, freed by
 * free_sequences. */
#define FILL_SAMPLE(s, k)                                                                                     \
  do {                                                                                                        \
    memset((s), 0, sizeof *(s));                                                                              \
    (s)->small = (int8_t)(-3 - (k));                                                                          \
    (s)->flag = (uint8_t)(200 + (k));                                                                         \
    (s)->big = -1234567890123LL * ((k) + 1);                                                                  \
    (s)->on = (k) % 2 != 0;                                                                                   \
    strcpy((s)->name, kNames[k]);                                                                             \
    (s)->points._length = (s)->points._maximum = (uint32_t)((2 * (k)) % 5);                                   \
    (s)->points._buffer = calloc(4, sizeof *(s)->points._buffer);                                             \
    for (uint32_t i = 0; i < (s)->points._length; ++i) {                                                      \
      (s)->points._buffer[i].x = (int16_t)(-100 * (int)i - (k));                                              \
      (s)->points._buffer[i].y = (uint8_t)(i + 10 * (k));                                                     \
    }                                                                                                         \
    for (int i = 0; i < 2; ++i)                                                                               \
      for (int j = 0; j < 3; ++j) (s)->grid[i][j] = i * 10 + j + 0.5 * (k);                                   \
    (s)->pose.x = (k) + 0.25;                                                                                 \
    (s)->pose.y = -(k)-0.5;                                                                                   \
    (s)->pose.z = 1e10 + (k);                                                                                 \
    (s)->stamps._length = (s)->stamps._maximum = (uint32_t)(k);                                               \
    (s)->stamps._buffer = calloc(3, sizeof *(s)->stamps._buffer);                                             \
    for (uint32_t i = 0; i < (s)->stamps._length; ++i) (s)->stamps._buffer[i] = (int64_t)1 << (40 + i + (k)); \
    (s)->tail = (uint8_t)(0xA0 + (k));                                                                        \
    (s)->mode = (k) % 3;                                                                                      \
    (s)->modes._length = (s)->modes._maximum = (uint32_t)((k) + 1);                                           \
    (s)->modes._buffer = calloc(3, sizeof *(s)->modes._buffer);                                               \
    for (uint32_t i = 0; i < (s)->modes._length; ++i) (s)->modes._buffer[i] = (i + (k)) % 3;                  \
    strcpy((s)->labels[0], kLabels[k][0]);                                                                    \
    strcpy((s)->labels[1], kLabels[k][1]);                                                                    \
    (s)->bits._length = (s)->bits._maximum = (uint32_t)((k) + 2);                                             \
    (s)->bits._buffer = calloc(4, sizeof *(s)->bits._buffer);                                                 \
    for (uint32_t i = 0; i < (s)->bits._length; ++i) (s)->bits._buffer[i] = (i + (k)) % 2 != 0;               \
    (s)->ratio = 1.5f + (float)(k);                                                                           \
    (s)->count = (uint16_t)(65535 - (k));                                                                     \
    (s)->id = 4000000000u + (uint32_t)(k);                                                                    \
    (s)->last = (uint8_t)(0x5A + (k));                                                                        \
  } while (0)

#define FREE_SEQUENCES(s)      \
  do {                         \
    free((s)->points._buffer); \
    free((s)->stamps._buffer); \
    free((s)->modes._buffer);  \
    free((s)->bits._buffer);   \
  } while (0)

/* Whether two samples of one module hold the same values (sequences up to their lengths; a
 * Point's padding byte is not compared). */
#define DEFINE_SAME(T)                                                                                               \
  static bool same_##T(const T* a, const T* b) {                                                                     \
    bool same = a->small == b->small && a->flag == b->flag && a->big == b->big && a->on == b->on &&                  \
                strcmp(a->name, b->name) == 0 && a->points._length == b->points._length &&                           \
                memcmp(a->grid, b->grid, sizeof a->grid) == 0 && a->pose.x == b->pose.x && a->pose.y == b->pose.y && \
                a->pose.z == b->pose.z && a->stamps._length == b->stamps._length && a->tail == b->tail &&            \
                a->mode == b->mode && a->modes._length == b->modes._length &&                                        \
                strcmp(a->labels[0], b->labels[0]) == 0 && strcmp(a->labels[1], b->labels[1]) == 0 &&                \
                a->bits._length == b->bits._length && a->ratio == b->ratio && a->count == b->count &&                \
                a->id == b->id && a->last == b->last;                                                                \
    for (uint32_t i = 0; same && i < a->points._length; ++i)                                                         \
      same = a->points._buffer[i].x == b->points._buffer[i].x && a->points._buffer[i].y == b->points._buffer[i].y;   \
    for (uint32_t i = 0; same && i < a->stamps._length; ++i) same = a->stamps._buffer[i] == b->stamps._buffer[i];    \
    for (uint32_t i = 0; same && i < a->modes._length; ++i) same = a->modes._buffer[i] == b->modes._buffer[i];       \
    for (uint32_t i = 0; same && i < a->bits._length; ++i) same = a->bits._buffer[i] == b->bits._buffer[i];          \
    return same;                                                                                                     \
  }

DEFINE_SAME(cdrcheck_Sample)
DEFINE_SAME(cdrcheck_app_Sample)

/* One way of writing: the module (final or appendable), the version and the byte order. */
struct variant {
  bool appendable;
  int version; /* 1 or 2 */
  bool big_endian;
};

static const struct variant kVariants[] = {
    {false, 1, false}, {false, 2, false}, {true, 2, false}, {false, 1, true}, {false, 2, true}, {true, 2, true},
};
#define VARIANTS (sizeof kVariants / sizeof kVariants[0])

static const dds_topic_descriptor_t* descriptor(bool appendable) {
  return appendable ? &cdrcheck_app_Sample_desc : &cdrcheck_Sample_desc;
}

/* A writer and a reader of one topic with one data representation, and a serdata of the reader's
 * (kept for its sertype: what reading our bytes is checked against). */
struct endpoint {
  dds_entity_t writer;
  dds_entity_t reader;
  struct ddsi_serdata* witness;
};

static bool make_endpoint(dds_entity_t participant, const struct variant* v, struct endpoint* e) {
  char name[64];
  snprintf(name, sizeof name, "cdr_check_%s_xcdr%d", v->appendable ? "appendable" : "final", v->version);
  dds_qos_t* qos = dds_create_qos();
  const dds_data_representation_id_t id =
      v->version == 1 ? DDS_DATA_REPRESENTATION_XCDR1 : DDS_DATA_REPRESENTATION_XCDR2;
  dds_qset_data_representation(qos, 1, &id);
  dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  const dds_entity_t topic = dds_create_topic(participant, descriptor(v->appendable), name, qos, NULL);
  e->writer = topic < 0 ? topic : dds_create_writer(participant, topic, qos, NULL);
  e->reader = topic < 0 ? topic : dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  e->witness = NULL;
  return topic >= 0 && e->writer >= 0 && e->reader >= 0;
}

/* Sample k through the writer; the serialized sample the reader got. */
static struct ddsi_serdata* written(const struct endpoint* e, const struct variant* v, int k) {
  cdrcheck_Sample f;
  cdrcheck_app_Sample a;
  dds_return_t rc;
  if (v->appendable) {
    FILL_SAMPLE(&a, k);
    rc = dds_write(e->writer, &a);
    FREE_SEQUENCES(&a);
  } else {
    FILL_SAMPLE(&f, k);
    rc = dds_write(e->writer, &f);
    FREE_SEQUENCES(&f);
  }
  struct ddsi_serdata* sd = NULL;
  dds_sample_info_t info;
  if (rc != DDS_RETCODE_OK || dds_takecdr(e->reader, &sd, 1, &info, 0) != 1) return NULL;
  return sd;
}

static void print_line(const struct variant* v, int k, const unsigned char* bytes, size_t size) {
  printf("%d %s xcdr%d %s ", k, v->appendable ? "appendable" : "final", v->version, v->big_endian ? "be" : "le");
  for (size_t i = 0; i < size; ++i) printf("%02x", bytes[i]);
  printf("\n");
}

/* The big-endian sample: Cyclone's stream writer's body, the header and padding by its rule. */
static bool write_big_endian(const struct variant* v, int k) {
  dds_ostreamBE_t os;
  dds_ostreamBE_init(&os, 0, (uint32_t)v->version);
  cdrcheck_Sample f;
  cdrcheck_app_Sample a;
  if (v->appendable) {
    FILL_SAMPLE(&a, k);
    dds_stream_writeBE(&os, (const char*)&a, descriptor(true)->m_ops);
    FREE_SEQUENCES(&a);
  } else {
    FILL_SAMPLE(&f, k);
    dds_stream_writeBE(&os, (const char*)&f, descriptor(false)->m_ops);
    FREE_SEQUENCES(&f);
  }
  const uint32_t body = os.x.m_index;
  const uint32_t pad = (4 - body % 4) % 4;
  unsigned char* bytes = calloc(4 + body + pad, 1);
  bytes[1] = v->version == 1 ? 0x00 : v->appendable ? 0x08 : 0x06; /* CDR_BE, D_CDR2_BE, CDR2_BE */
  bytes[3] = (unsigned char)pad;
  memcpy(bytes + 4, os.x.m_buffer, body);
  print_line(v, k, bytes, 4 + body + pad);
  free(bytes);
  dds_ostreamBE_fini(&os);
  return true;
}

static int write_all(struct endpoint* endpoints) {
  for (size_t i = 0; i < VARIANTS; ++i) {
    const struct variant* v = &kVariants[i];
    for (int k = 0; k < SAMPLES; ++k) {
      if (v->big_endian) {
        write_big_endian(v, k);
        continue;
      }
      struct ddsi_serdata* sd = written(&endpoints[i], v, k);
      if (sd == NULL) {
        fprintf(stderr, "cyclone-cdr-peer: writing sample %d failed\n", k);
        return 1;
      }
      const uint32_t size = ddsi_serdata_size(sd);
      unsigned char* bytes = malloc(size);
      ddsi_serdata_to_ser(sd, 0, size, bytes);
      print_line(v, k, bytes, size);
      free(bytes);
      ddsi_serdata_unref(sd);
    }
  }
  return 0;
}

static int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

/* Our sample through Cyclone's receive path, compared with sample k. */
static const char* check_sample(const struct ddsi_sertype* type, bool appendable, int k, unsigned char* bytes,
                                size_t size) {
  ddsrt_iovec_t iov = {.iov_base = bytes, .iov_len = (ddsrt_iov_len_t)size};
  struct ddsi_serdata* sd = ddsi_serdata_from_ser_iov(type, SDK_DATA, 1, &iov, size);
  if (sd == NULL) return "Cyclone refused the sample";
  bool same = false;
  if (appendable) {
    cdrcheck_app_Sample got, want;
    memset(&got, 0, sizeof got);
    const bool ok = ddsi_serdata_to_sample(sd, &got, NULL, NULL);
    FILL_SAMPLE(&want, k);
    same = ok && same_cdrcheck_app_Sample(&got, &want);
    FREE_SEQUENCES(&want);
    ddsi_sertype_free_sample(type, &got, DDS_FREE_CONTENTS);
  } else {
    cdrcheck_Sample got, want;
    memset(&got, 0, sizeof got);
    const bool ok = ddsi_serdata_to_sample(sd, &got, NULL, NULL);
    FILL_SAMPLE(&want, k);
    same = ok && same_cdrcheck_Sample(&got, &want);
    FREE_SEQUENCES(&want);
    ddsi_sertype_free_sample(type, &got, DDS_FREE_CONTENTS);
  }
  ddsi_serdata_unref(sd);
  return same ? NULL : "Cyclone read other values";
}

static int read_all(struct endpoint* endpoints) {
  char line[8192], ext[16], version[8], order[8], hex[8000];
  int k = 0, failures = 0, samples = 0;
  while (fgets(line, sizeof line, stdin) != NULL) {
    if (sscanf(line, "%d %15s %7s %7s %7999s", &k, ext, version, order, hex) != 5 || k < 0 || k >= SAMPLES) {
      fprintf(stderr, "cyclone-cdr-peer: bad line: %s", line);
      return 2;
    }
    const bool appendable = strcmp(ext, "appendable") == 0;
    const int v = strcmp(version, "xcdr2") == 0 ? 2 : 1;
    const struct endpoint* e = NULL;
    for (size_t i = 0; i < VARIANTS; ++i) {
      if (kVariants[i].appendable == appendable && kVariants[i].version == v && !kVariants[i].big_endian)
        e = &endpoints[i];
    }
    const size_t size = strlen(hex) / 2;
    unsigned char* bytes = malloc(size + 1);
    for (size_t i = 0; i < size; ++i)
      bytes[i] = (unsigned char)(hex_value(hex[2 * i]) * 16 + hex_value(hex[2 * i + 1]));
    const char* why = e == NULL ? "no such variant" : check_sample(e->witness->type, appendable, k, bytes, size);
    free(bytes);
    printf("%s %d %s %s %s %s\n", why == NULL ? "ok" : "FAIL", k, ext, version, order, why == NULL ? "" : why);
    failures += why != NULL;
    ++samples;
  }
  return failures == 0 && samples > 0 ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc != 2 || (strcmp(argv[1], "write") != 0 && strcmp(argv[1], "read") != 0)) {
    fprintf(stderr, "usage: cosmic-cyclone-cdr-peer write|read\n");
    return 2;
  }
  const dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
  if (participant < 0) return 3;
  struct endpoint endpoints[VARIANTS];
  for (size_t i = 0; i < VARIANTS; ++i) {
    if (kVariants[i].big_endian) continue;
    if (!make_endpoint(participant, &kVariants[i], &endpoints[i])) return 3;
    /* A serdata of this topic, for its sertype. */
    endpoints[i].witness = written(&endpoints[i], &kVariants[i], 0);
    if (endpoints[i].witness == NULL) return 3;
  }
  const int rc = strcmp(argv[1], "write") == 0 ? write_all(endpoints) : read_all(endpoints);
  for (size_t i = 0; i < VARIANTS; ++i) {
    if (!kVariants[i].big_endian) ddsi_serdata_unref(endpoints[i].witness);
  }
  dds_delete(participant);
  return rc;
}
