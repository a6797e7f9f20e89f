/* The types cosmic-cyclone-idl-peer (cyclone_idl_peer.c) knows: a table the test writes next to
 * the C code idlc generated (idlc_check_test.py), naming each struct's topic descriptor. */
#ifndef COSMIC_CYCLONE_IDL_PEER_H
#define COSMIC_CYCLONE_IDL_PEER_H

#include <stddef.h>

#include "dds/dds.h"

struct peer_type {
  const char* name; /* scoped, as the IDL declares it: "pkg::msg::Name" */
  const dds_topic_descriptor_t* descriptor;
};

extern const struct peer_type kPeerTypes[];
extern const size_t kPeerTypeCount;

#endif
