/* cosmic-cyclone-qos-peer / cosmic-cyclone-appendable-peer: an Eclipse Cyclone DDS (0.10, C API)
 * reader or writer of cosmic::Envelope whose QoS or type Cyclone itself finds incompatible with
 * cosmicd's endpoints, while Fast DDS 2.9 (inside cosmicd) does not check those rules and counts
 * the endpoint as matched (issue 22, item 11). Built twice from this file: with the envelope
 * generated from the project's Envelope.idl (@final) and with envelope_appendable.idl (the same
 * type name, @appendable, as idlc makes an unannotated struct).
 *
 *   PEER reader|writer --domain D --topic T [--representation xcdr1|xcdr2|default]
 *                      [--latency-budget-ms N] [--timeout-s S]
 *
 * Creates one endpoint with default QoS except what the options say (--representation: the one
 * a writer offers / the only one a reader accepts; default: Cyclone's choice for the type), prints
 * "ready" on stderr, then "INCOMPATIBLE policy=P" whenever Cyclone refuses a cosmicd endpoint for
 * its QoS (P: Cyclone's policy id of the last refusal) and "MATCHED" when it matches one. A writer
 * writes one envelope every 10 ms meanwhile. It ends on EOF on stdin or after S seconds (default
 * 60) and prints one JSON line on stdout:
 *   {"role":"reader","matched":M,"incompatible":I,"received":N,"representation":"XCDR2"}
 * (writer: "written" for "received"). Exit 0; 2: bad arguments; 3: entity creation failed.
 * Network: Cyclone DDS reads CYCLONEDDS_URI as usual (the tests enable multicast on loopback).
 */
#include <poll.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dds/dds.h"

#include PEER_TYPE_HEADER
#include "peer_args.h"

struct options {
  bool writer;
  const char* topic;
  long domain;
  const char* representation;
  long latency_budget_ms;
  long timeout_s;
};

static bool parse(int argc, char** argv, struct options* o) {
  memset(o, 0, sizeof *o);
  o->domain = -1;
  o->representation = "default";
  o->latency_budget_ms = -1;
  o->timeout_s = 60;
  if (argc < 2 || argc % 2 != 0) return false;
  if (strcmp(argv[1], "writer") != 0 && strcmp(argv[1], "reader") != 0) return false;
  o->writer = strcmp(argv[1], "writer") == 0;
  for (int i = 2; i + 1 < argc; i += 2) {
    const char *key = argv[i], *value = argv[i + 1];
    bool ok = true;
    if (strcmp(key, "--topic") == 0)
      o->topic = value;
    else if (strcmp(key, "--domain") == 0)
      ok = parse_long(value, &o->domain);
    else if (strcmp(key, "--representation") == 0)
      o->representation = value;
    else if (strcmp(key, "--latency-budget-ms") == 0)
      ok = parse_long(value, &o->latency_budget_ms);
    else if (strcmp(key, "--timeout-s") == 0)
      ok = parse_long(value, &o->timeout_s);
    else
      ok = false;
    if (!ok) return false;
  }
  const bool known = strcmp(o->representation, "default") == 0 || strcmp(o->representation, "xcdr1") == 0 ||
                     strcmp(o->representation, "xcdr2") == 0;
  return known && o->topic != NULL && o->domain >= 0 && o->domain <= 232 && o->timeout_s > 0;
}

static const char* representation_of(dds_entity_t entity) {
  dds_qos_t* qos = dds_create_qos();
  const char* name = "unknown";
  uint32_t n = 0;
  dds_data_representation_id_t* ids = NULL;
  if (dds_get_qos(entity, qos) == DDS_RETCODE_OK && dds_qget_data_representation(qos, &n, &ids) && n > 0) {
    if (n > 1)
      name = "XCDR1+XCDR2";
    else
      name = ids[0] == DDS_DATA_REPRESENTATION_XCDR2 ? "XCDR2" : "XCDR1";
  }
  dds_free(ids);
  dds_delete_qos(qos);
  return name;
}

/* What Cyclone says about cosmicd's endpoints: matched now, and refused for QoS so far. */
static void status_of(dds_entity_t entity, bool writer, long* matched, long* incompatible, long* policy) {
  if (writer) {
    dds_publication_matched_status_t m;
    dds_offered_incompatible_qos_status_t q;
    *matched = dds_get_publication_matched_status(entity, &m) == DDS_RETCODE_OK ? (long)m.current_count : -1;
    const bool ok = dds_get_offered_incompatible_qos_status(entity, &q) == DDS_RETCODE_OK;
    *incompatible = ok ? (long)q.total_count : -1;
    *policy = ok ? (long)q.last_policy_id : -1;
  } else {
    dds_subscription_matched_status_t m;
    dds_requested_incompatible_qos_status_t q;
    *matched = dds_get_subscription_matched_status(entity, &m) == DDS_RETCODE_OK ? (long)m.current_count : -1;
    const bool ok = dds_get_requested_incompatible_qos_status(entity, &q) == DDS_RETCODE_OK;
    *incompatible = ok ? (long)q.total_count : -1;
    *policy = ok ? (long)q.last_policy_id : -1;
  }
}

/* True once stdin is at EOF (the test's way of ending the peer). */
static bool stdin_closed(void) {
  struct pollfd p = {.fd = 0, .events = POLLIN};
  if (poll(&p, 1, 0) <= 0) return false;
  char buffer[64];
  return read(0, buffer, sizeof buffer) <= 0;
}

int main(int argc, char** argv) {
  struct options o;
  if (!parse(argc, argv, &o)) {
    fprintf(stderr,
            "usage: %s reader|writer --domain D --topic T [--representation xcdr1|xcdr2|default] "
            "[--latency-budget-ms N] [--timeout-s S]\n",
            argv[0]);
    return 2;
  }
  const dds_entity_t participant = dds_create_participant((dds_domainid_t)o.domain, NULL, NULL);
  if (participant < 0) return 3;
  const dds_entity_t topic = dds_create_topic(participant, &cosmic_Envelope_desc, o.topic, NULL, NULL);
  if (topic < 0) {
    fprintf(stderr, "cannot create topic %s: %s\n", o.topic, dds_strretcode(topic));
    return 3;
  }
  dds_qos_t* qos = dds_create_qos();
  if (strcmp(o.representation, "default") != 0) {
    const dds_data_representation_id_t id =
        strcmp(o.representation, "xcdr2") == 0 ? DDS_DATA_REPRESENTATION_XCDR2 : DDS_DATA_REPRESENTATION_XCDR1;
    dds_qset_data_representation(qos, 1, &id);
  }
  if (o.latency_budget_ms >= 0) dds_qset_latency_budget(qos, DDS_MSECS(o.latency_budget_ms));
  if (o.writer) dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  const dds_entity_t entity =
      o.writer ? dds_create_writer(participant, topic, qos, NULL) : dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  if (entity < 0) {
    fprintf(stderr, "cannot create the %s: %s\n", o.writer ? "writer" : "reader", dds_strretcode(entity));
    return 3;
  }
  fprintf(stderr, "ready (%s)\n", representation_of(entity));

  const dds_time_t deadline = dds_time() + DDS_SECS(o.timeout_s);
  long matched = 0, incompatible = 0, policy = 0, reported_incompatible = 0, count = 0;
  bool announced_match = false;
  uint8_t payload[4] = {1, 2, 3, 4};
  while (dds_time() < deadline && !stdin_closed()) {
    status_of(entity, o.writer, &matched, &incompatible, &policy);
    if (incompatible > reported_incompatible) {
      fprintf(stderr, "INCOMPATIBLE policy=%ld\n", policy);
      reported_incompatible = incompatible;
    }
    if (matched > 0 && !announced_match) {
      fprintf(stderr, "MATCHED\n");
      announced_match = true;
    }
    if (o.writer) {
      cosmic_Envelope e;
      memset(&e, 0, sizeof e);
      e.subject = 0x501;
      e.sequence = (uint32_t)(count + 1);
      e.payload._buffer = payload;
      e.payload._length = e.payload._maximum = sizeof payload;
      if (dds_write(entity, &e) == DDS_RETCODE_OK) ++count;
    } else {
      void* samples[1] = {NULL};
      dds_sample_info_t info[1];
      while (dds_take(entity, samples, info, 1, 1) > 0) {
        if (info[0].valid_data) ++count;
        dds_return_loan(entity, samples, 1);
      }
    }
    dds_sleepfor(DDS_MSECS(10));
  }
  status_of(entity, o.writer, &matched, &incompatible, &policy);
  printf("{\"role\":\"%s\",\"matched\":%ld,\"incompatible\":%ld,\"%s\":%ld,\"representation\":\"%s\"}\n",
         o.writer ? "writer" : "reader", matched, incompatible, o.writer ? "written" : "received", count,
         representation_of(entity));
  fflush(stdout);
  dds_delete(participant);
  return 0;
}
