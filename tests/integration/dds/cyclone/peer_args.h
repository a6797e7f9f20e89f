/* Command-line helpers shared by the Cyclone DDS test peers (cyclone_ros2_peer.c,
 * cyclone_qos_peer.c). */
#ifndef COSMIC_CYCLONE_PEER_ARGS_H
#define COSMIC_CYCLONE_PEER_ARGS_H

#include <stdbool.h>
#include <stdlib.h>

/* A whole decimal number, nothing else: "12" yes, "12x" or "" no. */
static inline bool parse_long(const char* text, long* out) {
  char* end = NULL;
  const long value = strtol(text, &end, 10);
  if (end == text || *end != '\0') return false;
  *out = value;
  return true;
}

#endif
