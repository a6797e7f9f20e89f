/* cosmic-cyclone-idl-peer: Eclipse Cyclone DDS (0.10, C API) reading and writing samples of any
 * struct idlc generated C code for, for the cross-check of the gateway's IDL reader
 * (idlc_check_test.py; the other side is cosmic-cdr-peer's IDL modes, tests/peers/cdr_peer_idl.cpp,
 * whose type comes from the gateway's own reading of the same .idl file).
 *
 *   cosmic-cyclone-idl-peer NAME   lines "K VERSION HEX" on stdin (samples cosmic wrote in VERSION,
 *                                  xcdr1 or xcdr2), one line each on stdout:
 *                                    "ok K VERSION TEXT HEX": Cyclone's receive path read it
 *                                      (ddsi_serdata_from_ser_iov, which checks the sample with
 *                                      dds_stream_normalize), TEXT is the sample as its
 *                                      ddsi_serdata_print shows it, HEX the same values written by
 *                                      Cyclone (ddsi_serdata_to_sample, dds_write, dds_takecdr,
 *                                      ddsi_serdata_to_ser: as it would go on the wire);
 *                                    "FAIL K VERSION why" otherwise.
 *
 * The struct NAME is looked up in the table of cyclone_idl_peer.h. Its generated C type is never
 * named here: samples are allocated by the descriptor's size and freed by its ops, so one peer
 * serves every type. Exit 0: every sample read and written; 1: one was not; 2: bad arguments;
 * 3: DDS entity creation failed.
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/dds.h"
#include "dds/ddsi/ddsi_serdata.h"
#include "dds/ddsi/ddsi_sertype.h"

#include "cyclone_idl_peer.h"

/* A writer and a reader of one topic in one data representation, and a serdata of the reader's
 * (kept for its sertype: what reading our bytes is checked against). */
struct endpoint {
  dds_entity_t writer;
  dds_entity_t reader;
  struct ddsi_serdata* witness;
};

static struct ddsi_serdata* write_and_take(const struct endpoint* e, const void* sample) {
  struct ddsi_serdata* sd = NULL;
  dds_sample_info_t info;
  if (dds_write(e->writer, sample) != DDS_RETCODE_OK || dds_takecdr(e->reader, &sd, 1, &info, 0) != 1) return NULL;
  return sd;
}

/* version 1 or 2; false when Cyclone refuses it (XCDR1 for an appendable type). */
static bool make_endpoint(dds_entity_t participant, const dds_topic_descriptor_t* d, int version, struct endpoint* e) {
  char name[32];
  snprintf(name, sizeof name, "idl_check_xcdr%d", version);
  dds_qos_t* qos = dds_create_qos();
  const dds_data_representation_id_t id = version == 1 ? DDS_DATA_REPRESENTATION_XCDR1 : DDS_DATA_REPRESENTATION_XCDR2;
  dds_qset_data_representation(qos, 1, &id);
  dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  const dds_entity_t topic = dds_create_topic(participant, d, name, qos, NULL);
  e->writer = topic < 0 ? topic : dds_create_writer(participant, topic, qos, NULL);
  e->reader = topic < 0 ? topic : dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  e->witness = NULL;
  if (topic < 0 || e->writer < 0 || e->reader < 0) return false;
  void* zero = dds_alloc(d->m_size);
  memset(zero, 0, d->m_size);
  e->witness = write_and_take(e, zero);
  dds_sample_free(zero, d, DDS_FREE_ALL);
  return e->witness != NULL;
}

static int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

/* Our sample through Cyclone's receive path, then written again by Cyclone. */
static bool check_sample(const dds_topic_descriptor_t* d, const struct endpoint* e, int k, const char* version,
                         unsigned char* bytes, size_t size) {
  ddsrt_iovec_t iov = {.iov_base = bytes, .iov_len = (ddsrt_iov_len_t)size};
  struct ddsi_serdata* sd = ddsi_serdata_from_ser_iov(e->witness->type, SDK_DATA, 1, &iov, size);
  if (sd == NULL) {
    printf("FAIL %d %s Cyclone refused the sample\n", k, version);
    return false;
  }
  static char text[1 << 16];
  ddsi_serdata_print(sd, text, sizeof text);
  void* sample = dds_alloc(d->m_size);
  memset(sample, 0, d->m_size);
  const bool read = ddsi_serdata_to_sample(sd, sample, NULL, NULL);
  ddsi_serdata_unref(sd);
  struct ddsi_serdata* again = read ? write_and_take(e, sample) : NULL;
  dds_sample_free(sample, d, DDS_FREE_ALL);
  if (again == NULL) {
    printf("FAIL %d %s Cyclone did not write the sample it read\n", k, version);
    return false;
  }
  const uint32_t out_size = ddsi_serdata_size(again);
  unsigned char* out = malloc(out_size);
  ddsi_serdata_to_ser(again, 0, out_size, out);
  ddsi_serdata_unref(again);
  printf("ok %d %s %s ", k, version, text);
  for (uint32_t i = 0; i < out_size; ++i) printf("%02x", out[i]);
  printf("\n");
  free(out);
  return true;
}

static int run(const dds_topic_descriptor_t* d, struct endpoint endpoints[2], const bool available[2]) {
  static char line[1 << 17], hex[1 << 17];
  char version[8];
  int k = 0, failures = 0, samples = 0;
  while (fgets(line, sizeof line, stdin) != NULL) {
    if (sscanf(line, "%d %7s %131071s", &k, version, hex) != 3) {
      fprintf(stderr, "cyclone-idl-peer: bad line: %s", line);
      return 2;
    }
    const int v = strcmp(version, "xcdr2") == 0 ? 1 : 0;
    const size_t size = strlen(hex) / 2;
    unsigned char* bytes = malloc(size + 1);
    for (size_t i = 0; i < size; ++i)
      bytes[i] = (unsigned char)(hex_value(hex[2 * i]) * 16 + hex_value(hex[2 * i + 1]));
    if (!available[v]) {
      printf("FAIL %d %s Cyclone has no topic in this representation\n", k, version);
      ++failures;
    } else if (!check_sample(d, &endpoints[v], k, version, bytes, size)) {
      ++failures;
    }
    free(bytes);
    ++samples;
  }
  return failures == 0 && samples > 0 ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: cosmic-cyclone-idl-peer NAME\n");
    return 2;
  }
  const dds_topic_descriptor_t* d = NULL;
  for (size_t i = 0; i < kPeerTypeCount; ++i) {
    if (strcmp(kPeerTypes[i].name, argv[1]) == 0) d = kPeerTypes[i].descriptor;
  }
  if (d == NULL) {
    fprintf(stderr, "cyclone-idl-peer: no type %s\n", argv[1]);
    return 2;
  }
  const dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
  if (participant < 0) return 3;
  struct endpoint endpoints[2];
  bool available[2];
  for (int v = 0; v < 2; ++v) available[v] = make_endpoint(participant, d, v + 1, &endpoints[v]);
  if (!available[0] && !available[1]) return 3;
  const int rc = run(d, endpoints, available);
  for (int v = 0; v < 2; ++v) {
    if (available[v]) ddsi_serdata_unref(endpoints[v].witness);
  }
  dds_delete(participant);
  return rc;
}
