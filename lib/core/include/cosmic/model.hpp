// The domain model of COSMIC event channels (Kaiser et al., sections 3-4) as the gateway sees it:
// segments (attached networks with their declared properties) and channels (subject, class,
// temporal attributes, publisher and subscriber segments). Plain values, owned by whoever holds
// the Config; no I/O.
#pragma once

#include <array>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/channel_class.hpp"
#include "cosmic/channel_type.hpp"
#include "cosmic/secret_key.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

enum class SegmentType { can, dds, lcm, replay };
enum class Reliability { reliable, best_effort };
enum class LcmEncoding { envelope, raw };

const char* to_string(ChannelClass value);
const char* to_string(SegmentType value);
const char* to_string(Reliability value);

// Fault hypothesis of a CAN bus: at most `max_per_window` error frames in any interval of length
// `window`. max_per_window == 0 means an error-free bus.
struct CanFaultHypothesis {
  std::uint32_t max_per_window = 0;
  Nanos window{Nanos::zero()};
  friend bool operator==(const CanFaultHypothesis&, const CanFaultHypothesis&) = default;
};

// Wire profile of a CAN segment (docs/can-wire-format.md): this project's layout, or FAMOUSO's
// (7-bit priority, fragment flag, CCP node ids, etag-4 binding answers, AFP fragments).
enum class CanProfile { cosmic, famouso };

// A frame that other devices send on a CAN bus (an ECU's DBC message, a frame declared in the
// YAML): it delays the gateway's frames like any frame does (interference when its identifier
// wins arbitration, blocking when it loses), so the response-time analysis and the bus load count it.
struct CanBackgroundFrame {
  std::string name;          // the DBC message's name, or "0x123" / "0x18FF0001x" from the YAML
  std::uint32_t can_id = 0;  // 11 or 29 bits, without flags
  bool extended = false;     // 29-bit identifier
  std::uint32_t length = 0;  // data bytes (FD: one of the FD lengths)
  Nanos period{0};           // minimum inter-arrival time (> 0)
  Nanos jitter{0};           // queuing jitter
  std::string origin;        // where it was declared: "body.dbc:12:1" or "robot.yaml:20:9"
  // Another gateway's frame of an HRT channel (federation): the longest response time it may have
  // with that channel still admitted there. A bind here that would push it beyond is rejected.
  std::optional<Nanos> deadline;
  friend bool operator==(const CanBackgroundFrame&, const CanBackgroundFrame&) = default;
};

struct CanSegmentProperties {
  std::string interface;
  CanProfile profile = CanProfile::cosmic;
  BitRate bitrate{500'000};
  bool fd = false;
  BitRate data_bitrate{0};  // FD data phase; equals bitrate when not FD or not given
  CanFaultHypothesis errors;
  std::vector<CanBackgroundFrame> background;  // other devices' frames (segment key `background`)
  friend bool operator==(const CanSegmentProperties&, const CanSegmentProperties&) = default;
};

// DDS Security on a DDS segment (segment key `security`, docs/security.md): every participant of
// the segment authenticates with this identity (PKI-DH), is held to the signed governance and
// permissions (Access-Permissions) and protects what they say (AES-GCM-GMAC), through Fast DDS's
// builtin plugins. Paths are absolute; the loader has checked the files (cosmic/dds_security_files.hpp).
struct DdsSecuritySpec {
  std::string identity_ca;
  std::string certificate;
  std::string private_key;
  std::string permissions_ca;
  std::string governance;
  std::string permissions;
  std::string subject;             // the certificate's subject ("/O=cosmic/CN=gateway-a")
  std::uint64_t content_hash = 0;  // of the six files' bytes: a reload sees a file changed in place
  // What the plugins' cryptography adds to one sample's hop at worst on this machine (`cost`, as
  // `cosmicctl calibrate` measures it, cosmic/dds_security_timing.hpp): admission adds it to the hop's latency.
  // None: not counted.
  std::optional<Nanos> cost{};
  friend bool operator==(const DdsSecuritySpec&, const DdsSecuritySpec&) = default;
};

struct DdsSegmentProperties {
  std::uint32_t domain = 0;
  std::vector<std::string> interfaces;  // allow-list of IPv4 addresses or interface names
  std::string discovery_server;         // "IP:PORT", empty for simple discovery
  // By class (hrt, srt, nrt): whether that class's participant also uses Fast DDS's shared-memory
  // transport to peers on this host (segment key `shared_memory`). Off for HRT by default: under
  // load the shared-memory path held HRT samples back for milliseconds, UDP did not (docs/yaml-reference.md).
  std::array<bool, 3> shared_memory{false, true, true};
  std::optional<DdsSecuritySpec> security{};
  friend bool operator==(const DdsSegmentProperties&, const DdsSegmentProperties&) = default;
};

// What the receive socket's filter does with the datagrams cosmicd itself sent, which multicast
// loopback hands back to it (docs/lcm-mapping.md): drop them in the kernel (never queued nor
// read, no wake-up; each counts in the host's UDP InErrors, cosmicd's own overflow count leaves
// them out and reports them as own_datagrams_dropped), or cut them to nothing (queued and read,
// no counter touched, at the price of a read and a wake-up of the receive thread per datagram sent).
enum class LcmOwnDatagrams { cut, drop };

// An LCM segment's authentication (segment key `auth`; cosmic/lcm_auth.hpp, docs/security.md):
// every envelope sent carries an HMAC-SHA256 trailer under `key`, and a received one without a
// valid trailer, or signed more than `window` away from this host's clock, or sent before, is
// dropped and counted.
struct LcmAuthSpec {
  std::string key_file;  // as resolved against the configuration's directory
  SecretKey key;
  // Keys whose tags are accepted besides `key`'s (`accept_key_files`: a key change in progress);
  // only `key` signs.
  std::vector<std::string> accepted_files{};
  std::vector<SecretKey> accepted{};
  Nanos window = std::chrono::seconds(1);
  // What signing or checking one message costs on this machine, worst case (`auth.cost`, as
  // `cosmicctl calibrate` measures it): admission adds it to the hop's latency. None: not counted.
  std::optional<Nanos> cost{};
  friend bool operator==(const LcmAuthSpec&, const LcmAuthSpec&) = default;
};

struct LcmSegmentProperties {
  std::string url = "udpm://239.255.76.67:7667?ttl=0";
  LcmOwnDatagrams own_datagrams = LcmOwnDatagrams::drop;
  std::optional<LcmAuthSpec> auth{};
  friend bool operator==(const LcmSegmentProperties&, const LcmSegmentProperties&) = default;
};

// One channel of a recording a replay segment publishes: how many events the recording holds of it
// and the tightest spacing of two of them as recorded (before `speed`).
struct ReplayStream {
  std::string channel;
  std::uint64_t events = 0;
  Nanos tightest{0};  // 0 with fewer than two events
  friend bool operator==(const ReplayStream&, const ReplayStream&) = default;
};

// A segment that publishes a recording into the channels it holds (issue 37, `type: replay`,
// docs/recording.md): the recorded events of the selected channels with their recorded spacing,
// divided by `speed`, from `start_offset` into the recording, over again with `loop`.
struct ReplaySegmentProperties {
  std::string file;                   // an MCAP recording, absolute
  std::vector<std::string> channels;  // names or fnmatch(3) globs; empty: every channel recorded
  double speed = 1.0;                 // 2: twice as fast as recorded
  bool loop = false;
  Nanos start_offset{0};
  // Read from the file at load (the loader's scan), one per recorded channel the selection takes, in
  // the order of their first events; and the file's bytes hashed, so a reload sees a changed file.
  std::vector<ReplayStream> streams;
  std::uint64_t content_hash = 0;
  const ReplayStream* stream(const std::string& channel) const;
  // Whether `channel` (a recorded topic) is among those `channels` selects.
  bool selects(const std::string& channel) const;
  friend bool operator==(const ReplaySegmentProperties&, const ReplaySegmentProperties&) = default;
};

struct SegmentSpec {
  std::string name;
  SegmentType type = SegmentType::dds;
  double max_utilization = 0.7;  // share of the bandwidth the bus may reach (CAN: background included)
  // IP segments: declared network properties. CAN derives them from the bit rate.
  BitRate bandwidth{100'000'000};
  Nanos latency_bound{Nanos(10'000'000)};
  Reliability reliability = Reliability::reliable;
  bool realtime = false;                   // network guarantees latency_bound (e.g. TSN)
  std::uint64_t max_message_size = 65000;  // largest event the network carries in one message
  CanSegmentProperties can;
  DdsSegmentProperties dds;
  LcmSegmentProperties lcm;
  ReplaySegmentProperties replay;
  // Segment key `network`: the name of the network this segment attaches, the same on every
  // gateway attached to it (federation, docs/federation.md). CAN buses are shared only through it.
  std::string network;
  // Never configured: the share of the network that other gateways of the federation reserve
  // (IP segments; their CAN frames enter `can.background` instead). Set on the knowledge base's
  // copy of the segments only.
  double peer_load = 0;
  friend bool operator==(const SegmentSpec&, const SegmentSpec&) = default;
};

// A channel in a segment's own wire format (channel key `native`, issue 19): the identity that
// the devices already on that network use, instead of this project's envelope or identifier layout.
struct NativeCanFrame {
  std::uint32_t can_id = 0;  // 11 or 29 bits, without flags; the frame's data bytes are the contents
  bool extended = false;
  // A typed channel's signal-gateway hop (`native: {BUS: {dbc: FILE, message: NAME}}`): the frame is
  // this DBC message, not the type's own, its signals carrying the type's fields by name or as
  // field_map renames them (field -> signal; a nested record's field by its path, linear.x), but for
  // omitted_fields; can_id and extended are the message's. Optionally
  // protected end to end. Compared by content: a changed file rebinds the channel.
  std::optional<DbcMessage> dbc_message{};
  std::string dbc_file{};
  std::map<std::string, std::string> field_map{};
  std::vector<std::string> omitted_fields{};  // `omit`: the type's fields this message does not carry
  std::optional<E2eSpec> e2e{};
  friend bool operator==(const NativeCanFrame&, const NativeCanFrame&) = default;
};

// Which extended CDR version a native DDS writer announces (DataRepresentationQosPolicy); the bytes
// it is given must carry an encapsulation identifier of that version.
enum class DdsRepresentation { xcdr1, xcdr2 };
const char* to_string(DdsRepresentation value);

// A DDS topic of any type, carried as its serialized payload (encapsulation header included).
struct NativeDdsTopic {
  std::string topic;                                            // e.g. rt/cmd_vel (ROS 2: rt/<name>)
  std::string type;                                             // e.g. geometry_msgs::msg::dds_::Twist_
  DdsRepresentation representation = DdsRepresentation::xcdr1;  // what our writer announces
  friend bool operator==(const NativeDdsTopic&, const NativeDdsTopic&) = default;
};

// How a typed channel's events look on a native CAN or LCM hop (key `representation` under the
// hop's `native` entry; docs/typed-layout.md): the type source's own form (a DBC message's frame on
// CAN, the LCM type's encoding on LCM), the compact layout, or JSON (LCM, written for tools only).
// A native DDS hop carries CDR in the version NativeDdsTopic::representation names.
enum class NativeForm : std::uint8_t { source, compact, json };
const char* to_string(NativeForm value);

struct NativeBinding {
  std::string segment;
  std::optional<NativeCanFrame> can;       // CAN segments: the channel is this frame
  std::optional<std::string> lcm_channel;  // LCM segments: raw contents on this LCM channel name
  std::optional<NativeDdsTopic> dds;       // DDS segments: the serialized samples of this topic
  NativeForm form = NativeForm::source;    // CAN and LCM hops of a typed channel
  friend bool operator==(const NativeBinding&, const NativeBinding&) = default;
};
// How errors and reports name a native identity: "0x123", "0x18FF0001", the LCM channel name or
// the DDS topic name.
std::string native_identity(const NativeBinding& binding);

// A typed channel's hop as its representation says (cosmic/hop_representation.hpp): the most bytes
// of one message, the form's name, and what the form cannot carry of the type. Admission judges
// these: an unfit hop rejects the channel (check "representation"), a narrowed one degrades it
// (check "range"; an HRT channel is rejected).
struct HopPayload {
  std::string segment;
  std::uint64_t bytes = 0;
  std::string form;      // "DBC frame 0x1A0 WheelSpeed", "XCDR2", "compact"; empty when unfit
  std::string unfit;     // why the hop cannot carry the type (bytes is then 0); empty: it can
  std::string narrowed;  // the fields whose declared range the form holds only in part (saturated)
  friend bool operator==(const HopPayload&, const HopPayload&) = default;
};

// SecOC on one CAN hop of a channel (channel key `secoc: {SEGMENT: {...}}`, issue 36 item 4;
// docs/security.md): each frame of the channel on that segment carries, after its data, the low
// `freshness_bits` of a 64-bit freshness counter and the first `mac_bits` of an AES-128-CMAC over
// (data ID, data, complete freshness) - AUTOSAR's secured I-PDU (cosmic/secoc.hpp). The gateway
// protects what it sends there and drops (and counts) what it receives that is not authentic or
// is replayed.
struct SecocSpec {
  std::string segment;
  std::string key_file;  // as resolved against the configuration's directory
  SecretKey key;         // 16 bytes (AES-128)
  std::uint32_t mac_bits = 24;
  std::uint32_t freshness_bits = 8;
  // The MAC input's data ID; none: derived from each frame's identifier (the TxNode and etag of
  // this project's layout, the native identifier), so a frame cannot pass for another sender's.
  std::optional<std::uint32_t> data_id{};
  // What protecting or checking one frame costs on this machine at worst (`cosmicctl calibrate`):
  // admission adds it to the hop's latency. None: not counted.
  std::optional<Nanos> cost{};
  std::uint32_t overhead_bytes() const { return (mac_bits + freshness_bits) / 8; }
  friend bool operator==(const SecocSpec&, const SecocSpec&) = default;
};

// An FMU of the configuration that publishes a channel (`fmus:` outputs, docs/fmu.md): it
// publishes once per communication step, so admission compares its step with the channel's period
// and temp_validity on the FMU's publisher hop (checks "fmu_rate" and "fmu_validity").
struct FmuPublisher {
  std::string fmu;      // the FMU's name
  std::string segment;  // where its runner lives: one of the channel's publishers
  Nanos step{0};        // its communication step
  friend bool operator==(const FmuPublisher&, const FmuPublisher&) = default;
};

struct ChannelSpec {
  std::string name;
  std::uint64_t subject = 0;
  ChannelClass cls = ChannelClass::nrt;
  std::optional<Nanos> period;         // minimum inter-arrival time (from period or max_rate)
  std::optional<Nanos> reaction_time;  // end-to-end latency bound
  std::uint32_t omission_degree = 0;   // consecutive losses tolerated
  std::optional<Nanos> temp_validity;  // event is stale after this age
  std::uint64_t payload = 8;           // maximum payload bytes
  std::optional<std::uint16_t> etag;   // static CAN etag, otherwise assigned
  LcmEncoding lcm_encoding = LcmEncoding::envelope;
  std::vector<std::string> publishers;       // P segments
  std::vector<std::string> subscribers;      // S segments
  std::vector<NativeBinding> native;         // at most one per segment, each one of publishers/subscribers
  std::optional<ChannelType> type;           // the contents' fields (cosmic/channel_type.hpp); none: opaque bytes
  RangePolicy on_range = RangePolicy::drop;  // a typed channel's values a hop cannot hold
  // A typed channel: each hop's message size from its representation (derived by the configuration
  // with `payload`, which is then the largest of them); empty for an untyped channel.
  std::vector<HopPayload> hop_payloads;
  std::vector<SecocSpec> secoc;  // at most one per segment, each a CAN segment among publishers/subscribers
  // The FMUs publishing this channel, derived by the configuration from `fmus:` (a bound or
  // replaced channel from the running configuration's); empty when none does.
  std::vector<FmuPublisher> fmu_publishers{};
  friend bool operator==(const ChannelSpec&, const ChannelSpec&) = default;

  // The most bytes one event takes on `segment`: its hop's own size where the type gives one, else
  // `payload`.
  std::uint64_t payload_on(const std::string& segment) const;
  // A typed channel's hop on `segment` (hop_payloads), if the configuration derived one.
  const HopPayload* hop_on(const std::string& segment) const;

  const NativeBinding* native_on(const std::string& segment) const;
  // The SecOC protection of this channel's frames on `segment`, if it has one there.
  const SecocSpec* secoc_on(const std::string& segment) const;
  // The native CAN frame of this channel on `segment`, if it has one there.
  std::optional<NativeCanFrame> native_can(const std::string& segment) const;
  // The native DDS topic of this channel on `segment`, if it has one there.
  std::optional<NativeDdsTopic> native_dds(const std::string& segment) const;
};

// Opt-in HTTP endpoint serving the gateway's metrics (docs/metrics.md). Off unless configured.
struct MetricsSpec {
  bool enabled = false;
  std::string host;  // an IPv4 or IPv6 literal (IPv6 without brackets)
  std::uint16_t port = 0;
  bool allow_remote = false;  // true: the operator opted in to a non-loopback host
  friend bool operator==(const MetricsSpec&, const MetricsSpec&) = default;
};

// gateway.realtime.cpus: where each kind of cosmicd thread may run; an empty list: where `other`
// says (every thread is placed there first), any CPU when `other` is empty too. A
// deployment with a hard real-time path gives the HRT lanes (and the HRT DDS participants' threads,
// which inherit it) CPUs of their own and keeps every other thread off them: a time-shared thread
// in a long system call on an HRT CPU delays an HRT thread woken there until it leaves the kernel
// (docs/operations.md, "A CPU for the hard real-time path").
struct CpuPlacement {
  std::vector<int> hrt;      // the HRT egress lanes and the HRT DDS participants' threads
  std::vector<int> srt;      // the SRT egress lanes and the SRT DDS participants' threads
  std::vector<int> nrt;      // the NRT egress lanes
  std::vector<int> receive;  // the receive threads: CAN, LCM and the NRT DDS participants' (these
                             // also send NRT events to idle lanes while time-shared)
  std::vector<int> other;    // every other thread (control, metrics, logging, discovery)
  bool any() const { return !hrt.empty() || !srt.empty() || !nrt.empty() || !receive.empty() || !other.empty(); }
  const std::vector<int>& of(ChannelClass cls) const {
    return cls == ChannelClass::hrt ? hrt : cls == ChannelClass::srt ? srt : nrt;
  }
  friend bool operator==(const CpuPlacement&, const CpuPlacement&) = default;
};

// gateway.realtime: how the forwarding threads run. Priorities are SCHED_FIFO (1..99, 0 = the
// normal time-sharing class); without the privilege cosmicd runs on and says what it could not get.
struct RealtimeSpec {
  int hrt_priority = 0;      // the HRT egress lanes
  int srt_priority = 0;      // the SRT egress lanes
  int nrt_priority = 0;      // the NRT egress lanes (0: time sharing; nice 10 unless HRT and SRT run SCHED_FIFO)
  int receive_priority = 0;  // the adapters' receive threads that cosmicd owns (CAN, LCM)
  CpuPlacement cpus;         // CPU affinity of those threads and of the rest
  bool lock_memory = false;  // mlockall(MCL_CURRENT | MCL_FUTURE) at start
  bool requested() const {
    return hrt_priority || srt_priority || nrt_priority || receive_priority || cpus.any() || lock_memory;
  }
  friend bool operator==(const RealtimeSpec&, const RealtimeSpec&) = default;
};

// gateway.federation (docs/federation.md): the DDS segment over which this gateway announces
// itself and hears the others; off when `segment` is empty.
// A gateway whose announcements count on a secure federation segment (gateway.federation.peers,
// docs/federation.md): its identity certificate's subject, and the participant key prefixes DDS
// Security's PKI-DH gives a holder of that subject (cosmic/certificate_subject.hpp), by which an
// authenticated participant is told to be that gateway.
struct FederationPeerSpec {
  std::string subject;  // OpenSSL's one-line form, "/O=cosmic/CN=gateway-b"
  std::vector<std::array<std::uint8_t, 6>> key_prefixes;
  friend bool operator==(const FederationPeerSpec&, const FederationPeerSpec&) = default;
};

struct FederationSpec {
  std::string segment;
  Nanos lease{Nanos(3'000'000'000)};  // a peer silent (its participant's lease) this long is lost
  // A bind that adds load to a network other gateways share first claims it for this long, so a
  // concurrent bind on another gateway sees it (lower gateway id goes first).
  Nanos claim_window{Nanos(500'000'000)};
  // Only on a secure segment. Empty: every participant that authenticated (and that the
  // permissions let publish cosmic/federation) counts; else only these.
  std::vector<FederationPeerSpec> peers;
  bool enabled() const { return !segment.empty(); }
  friend bool operator==(const FederationSpec&, const FederationSpec&) = default;
};

struct GatewaySpec {
  std::string name = "cosmicd";
  std::uint8_t can_node_id = 1;
  Nanos residence_bound{Nanos(1'000'000)};      // worst-case time an event spends inside the gateway
  Nanos clean_interval{Nanos(10'000'000'000)};  // a violated channel is bound again after this long without a miss
  RealtimeSpec realtime;
  std::string control_socket = "/run/cosmicd/control.sock";
  MetricsSpec metrics;
  FederationSpec federation;
  friend bool operator==(const GatewaySpec&, const GatewaySpec&) = default;
};

// A component of the application (the paper's Event-Channel Diagram, Fig. 6): it lives on one
// segment and publishes (P) and/or subscribes (S) channels by name. cosmicd does not run
// components; tools read them (cosmicctl diagram, cosmicctl gen) and a channel without
// publishers/subscribers takes its P/S segments from them (docs/components.md).
struct ComponentSpec {
  std::string name;
  std::string segment;
  std::vector<std::string> publishes;   // channel names
  std::vector<std::string> subscribes;  // channel names
  // The subject of the component's DDS Security certificate in RFC 2253 form ("CN=detector,O=cosmic"),
  // for its grant in the permissions `cosmicctl security permissions` writes; empty: none declared.
  std::string subject{};
  friend bool operator==(const ComponentSpec&, const ComponentSpec&) = default;
};

// An FMU variable and the channel field it carries (`fmus:` inputs and outputs, docs/fmu.md): the
// field a path into the channel's type, dotted through nested records ("speed", "pose.x").
struct FmuVariableMapping {
  std::string variable;
  std::string channel;
  std::string field;
  friend bool operator==(const FmuVariableMapping&, const FmuVariableMapping&) = default;
};

// A parameter the runner sets before initialization, as written (checked against its type at load).
struct FmuParameter {
  std::string variable;
  std::string value;
  friend bool operator==(const FmuParameter&, const FmuParameter&) = default;
};

// A co-simulation FMU run as a component on one segment (issue 38, `fmus:`, docs/fmu.md): each step
// takes its inputs from channel fields and publishes its outputs. It counts as a component that
// publishes its output channels and subscribes its input channels; each output channel's
// ChannelSpec::fmu_publishers names it with its step, which admission judges.
struct FmuSpec {
  std::string name;
  std::string fmu;  // the FMU file, absolute (a relative one is anchored at the configuration)
  std::string segment;
  Nanos step{Nanos(10'000'000)};  // the communication step (given, or the FMU's DefaultExperiment stepSize)
  std::vector<FmuVariableMapping> inputs;
  std::vector<FmuVariableMapping> outputs;
  std::vector<FmuParameter> parameters;
  // Read from the FMU at load:
  std::string fmi_version;       // "2.0", "3.0"
  std::string model_identifier;  // its shared library's name
  // The channels its outputs set (inputs read), each once, in the order first mapped.
  std::vector<std::string> publishes() const;
  std::vector<std::string> subscribes() const;
  friend bool operator==(const FmuSpec&, const FmuSpec&) = default;
};

// What cosmicd records of the channels that cross it (issue 37; `recording:`, docs/recording.md):
// MCAP files in `directory`, of the channels whose names match `channels` (names or globs), and
// the CAN segments in `candump` also as `candump -l` logs.
enum class RecordCompression { zstd, none };
// How a typed channel's events are recorded: CDR with its ROS 2 message definition (what ROS 2
// tools and Foxglove decode; a type without that form falls back to JSON), or JSON with its JSON
// Schema.
enum class TypedEncoding { cdr, json };

struct RecordingSpec {
  std::string directory;              // absolute (the loader anchors a relative one at the file)
  std::vector<std::string> channels;  // names or fnmatch(3) globs; empty: every channel
  RecordCompression compression = RecordCompression::zstd;
  TypedEncoding typed_encoding = TypedEncoding::cdr;
  std::uint64_t chunk_size = 1u << 20;            // bytes of messages per MCAP chunk, before compression
  std::uint64_t rotate_size = 256u << 20;         // a new file when one holds this many bytes
  Nanos rotate_duration{Nanos(600'000'000'000)};  // or has been written this long
  std::uint64_t memory = 16u << 20;               // what events may wait for the writer, at most
  bool start = true;                              // recording from the start (else `cosmicctl record start`)
  std::vector<std::string> candump;               // CAN segments also logged as candump -l
  bool enabled() const { return !directory.empty(); }
  // Whether channel `name` is recorded (a name or glob of `channels` matches it).
  bool selects(const std::string& name) const;
  friend bool operator==(const RecordingSpec&, const RecordingSpec&) = default;
};

struct Config {
  GatewaySpec gateway;
  RecordingSpec recording;
  std::vector<SegmentSpec> segments;
  std::vector<ChannelSpec> channels;
  std::vector<ComponentSpec> components;  // optional application model, may be empty
  std::vector<FmuSpec> fmus;              // optional FMUs as components, may be empty

  const SegmentSpec* find_segment(const std::string& name) const;
  const ChannelSpec* find_channel(const std::string& name) const;
};

// How a component on `segment` opens it with libcosmic-client's cosmic_open(): "dds:DOMAIN"
// (with "?reliability=best_effort" on such a segment), "lcm:URL", "can:IFACE?node=N" (TxNode
// `can_node`); empty for a replay segment, where no component lives.
std::string client_segment(const SegmentSpec& segment, unsigned can_node);

}  // namespace cosmic
