/* libcosmic-client: join COSMIC event channels from a component (Kaiser et al., Fig. 9) without
 * hand-crafting CAN identifiers or DDS/LCM envelopes. A component names its channel (name and
 * subject, with the channel's class and QoS from the model) and the segment it lives on; the
 * library speaks the gateway's own formats there (docs/components.md):
 *   DDS  topic cosmic/<name>, type cosmic::Envelope, QoS derived from the channel as cosmicd does;
 *   LCM  channel <name>, type cosmic.envelope;
 *   CAN  29-bit identifiers of docs/can-wire-format.md; the etag is bound with GET_ETAG at
 *        cosmic_announce(), fragments for NRT events larger than one frame.
 * No addresses anywhere, and no admission: cosmic_check_channel() asks a running cosmicd.
 *
 * Ownership: cosmic_open() returns a client the caller frees with cosmic_close(), which also frees
 * every channel announced on it. Threads: every function may be called from any thread; each
 * client has its own receive thread(s), on which cosmic_subscribe() callbacks run (keep them
 * short: they delay the next event). The library never prints; cosmic_last_error() says why a
 * call failed.
 *
 * When callbacks run: a callback installed with cosmic_subscribe() is called on the receive
 * thread from the moment cosmic_subscribe() returns until one of these returns:
 *   cosmic_unsubscribe(channel) or cosmic_subscribe(channel, another, ...) on its channel, or
 *   cosmic_close(client).
 * Each of them waits for a call in progress to finish; after it returns the old callback is not
 * running and is never called again. So whatever a callback touches (its `user` data) may be freed
 * only after one of them returned: stop the callbacks first, then free the state they use. From
 * inside a callback, cosmic_unsubscribe()/cosmic_subscribe() of that same channel are allowed
 * (they take effect when the callback returns); cosmic_close() is not (it would wait for itself),
 * nor is changing another channel's callback (two receive threads could wait for each other). */
#ifndef COSMIC_CLIENT_H
#define COSMIC_CLIENT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cosmic_client cosmic_client;
typedef struct cosmic_channel cosmic_channel;

typedef enum { COSMIC_HRT = 0, COSMIC_SRT = 1, COSMIC_NRT = 2 } cosmic_class;

/* Roles of this component on a channel (bit mask). */
enum { COSMIC_PUBLISH = 1, COSMIC_SUBSCRIBE = 2 };

/* Results: 0 or a negative code. */
enum {
  COSMIC_OK = 0,
  COSMIC_E_INVALID = -1,     /* a bad argument (see cosmic_last_error) */
  COSMIC_E_TRANSPORT = -2,   /* the network refused (interface down, participant failed) */
  COSMIC_E_AGAIN = -3,       /* cosmic_get_event: no event waiting; publish: try again */
  COSMIC_E_TOO_LARGE = -4,   /* event larger than the channel's payload or the caller's buffer */
  COSMIC_E_UNBOUND = -5,     /* CAN: no gateway answered GET_ETAG for the subject */
  COSMIC_E_UNAVAILABLE = -6, /* cosmic_check_channel: the gateway cannot be reached */
  COSMIC_E_TIMEOUT = -7      /* cosmic_wait_ready: no peer matched within the timeout */
};

/* A channel as the model (the YAML) describes it. Durations in nanoseconds, 0 = not given. */
typedef struct {
  const char* name; /* the channel's name: DDS topic cosmic/<name>, LCM channel <name> */
  uint64_t subject; /* 64-bit subject UID */
  cosmic_class cls;
  int64_t period_ns;
  int64_t reaction_time_ns;
  int64_t temp_validity_ns;
  uint32_t omission_degree;
  uint32_t payload; /* largest event in bytes */
  int roles;        /* COSMIC_PUBLISH | COSMIC_SUBSCRIBE */
} cosmic_channel_desc;

typedef struct {
  uint64_t subject;
  uint32_t sequence; /* per publisher; 0 where the source has none (CAN) */
  int64_t age_ns;    /* time spent in transit before the last gateway forwarded it */
  uint32_t size;     /* bytes of the event */
} cosmic_event_info;

typedef void (*cosmic_event_fn)(const cosmic_event_info* info, const uint8_t* data, void* user);

/* Attaches to one segment:
 *   "dds:DOMAIN" or "dds:DOMAIN?reliability=best_effort"
 *   "lcm:udpm://GROUP:PORT?ttl=N" (or "lcm:memq://")
 *   "can:IFACE?node=N"  (N = this component's 7-bit TxNode, unique on the bus)
 * NULL on failure, with the reason in `error` (may be NULL). */
cosmic_client* cosmic_open(const char* segment, char* error, size_t error_size);
/* Stops the client's receive threads (waiting for a callback in progress), then frees the client and
 * its channels. When it returns no callback of this client runs. Never from inside a callback. */
void cosmic_close(cosmic_client* client);
const char* cosmic_last_error(const cosmic_client* client);

/* Sets up the channel for the roles in desc->roles (creates the DDS writer/reader, binds the CAN
 * etag: up to timeout_ms waiting for the gateway's SUPPLY_ETAG). NULL on failure. On DDS it
 * returns before any peer has matched: cosmic_wait_ready() waits until the channel is carried. */
cosmic_channel* cosmic_announce(cosmic_client* client, const cosmic_channel_desc* desc, int timeout_ms);
/* Waits up to timeout_ms until the channel is carried: every role announced on it has at least one
 * matched remote endpoint. COSMIC_PUBLISH: a reader (the gateway's, or another component's) has
 * matched this component's writer; COSMIC_SUBSCRIBE: a writer has matched its reader. Call it after
 * cosmic_announce() (which never waits for this) and before the first event that must not be lost:
 * events published before a reader matched are lost to it, and DDS discovery takes from
 * milliseconds to seconds (e.g. after `cosmicctl bind --replace` moved the channel's publisher to
 * this segment, the gateway's new reader appears there).
 * Returns COSMIC_OK once ready, at once when it already is (timeout_ms 0: a check without waiting);
 * COSMIC_E_TIMEOUT when timeout_ms passed first, with cosmic_last_error() naming the channel, the
 * segment, the role(s) still unmatched and the time waited; COSMIC_E_INVALID for a NULL channel
 * or a negative timeout_ms.
 * Per transport:
 *   DDS  waits for the matches (polled every millisecond). They are what this side of DDS sees;
 *        the remote end matches on its own side at about the same time. COSMIC_PUBLISH: the
 *        writer keeps its latest omission_degree + 1 events for a reader it matched until that
 *        reader has them, so a reliable reader (the gateway's on a reliable segment) gets what is
 *        published after COSMIC_OK even if its own side matches a little later. COSMIC_SUBSCRIBE:
 *        the remote writer may match this reader a little after this reader matched it, and what
 *        it sends before that does not reach this reader;
 *   LCM  COSMIC_OK at once: multicast has no discovery, a subscriber cannot be seen;
 *   CAN  COSMIC_OK at once: cosmic_announce() already waited for the gateway's SUPPLY_ETAG answer to
 *        GET_ETAG, which a gateway gives only for a channel it binds on that bus.
 * The channel stays announced and usable whatever this returns. From any thread, for any number of
 * channels at once; never from inside a callback (it would hold up the receive thread). */
int cosmic_wait_ready(cosmic_channel* channel, int timeout_ms);
/* One event of `size` bytes (at most desc->payload). */
int cosmic_publish(cosmic_channel* channel, const void* data, size_t size);
/* Events of the channel go to `fn` on the receive thread; fn NULL: they are queued for
 * cosmic_get_event() instead (the default; the newest 64 are kept). Replaces the previous
 * callback: when it returns, the previous one is not running and is never called again. */
int cosmic_subscribe(cosmic_channel* channel, cosmic_event_fn fn, void* user);
/* Stops the channel's callback: when it returns, the callback is not running (unless this is called
 * from inside it: then it is not called again after it returns) and is never called again; later
 * events are queued for cosmic_get_event(). The same as cosmic_subscribe(channel, NULL, NULL). */
int cosmic_unsubscribe(cosmic_channel* channel);
/* Takes the oldest queued event without waiting: COSMIC_OK, COSMIC_E_AGAIN when none waits,
 * COSMIC_E_TOO_LARGE when `capacity` is too small (the event stays queued; info->size says how
 * much is needed). For periodic tools (Simulink) that poll once per step. */
int cosmic_get_event(cosmic_channel* channel, cosmic_event_info* info, void* buffer, size_t capacity);

/* Asks the cosmicd at `control_socket` (docs/control-protocol.md) for the channel's verdict
 * ("bound", "degraded", "violated", "failed"); "rejected (REASONS)" for a channel of the gateway's
 * configuration that admission rejected; "not_found" when the gateway does not know it. */
int cosmic_check_channel(const char* control_socket, const char* name, char* verdict, size_t verdict_size);

#ifdef __cplusplus
}
#endif

#endif
