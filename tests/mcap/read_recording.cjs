// What the MCAP implementation we did not write (npm's @mcap/core, @mcap/nodejs, @mcap/support)
// reads of a file cosmicd recorded, as JSON on standard output for the tests to check.
//   node read_recording.cjs indexed FILE
//     McapIndexedReader (summary, chunk indexes, statistics): channels, schemas, statistics, the
//     number of chunk indexes, and every message in log-time order with its topic (a `json`
//     message parsed; a `cdr` one decoded by @foxglove/rosmsg2-serialization's MessageReader with
//     its `ros2msg` schema as @foxglove/rosmsg parses it, 64-bit integers as decimal strings and
//     typed arrays as arrays; others as hex); `ordered` says whether the log times never went back.
//   node read_recording.cjs stream FILE
//     McapStreamReader over the bytes as they are (a file cut short by a crash): the channels and
//     messages of every complete record, and whether the reader reached the end of a whole file.
// Run with NODE_PATH naming the node_modules of tests/mcap's `npm ci`.
"use strict";

const fs = require("node:fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { FileHandleReadable } = require("@mcap/nodejs");
const { loadDecompressHandlers } = require("@mcap/support");
const { parse: parseMessageDefinition } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");

const text = (bytes) => Buffer.from(bytes).toString("utf8");

// What MessageReader decoded, as JSON can carry it: BigInt (int64, uint64) as its decimal text,
// typed arrays (numeric arrays and sequences) as plain arrays.
function plain(value) {
  if (typeof value === "bigint") return value.toString();
  if (ArrayBuffer.isView(value)) return Array.from(value, plain);
  if (Array.isArray(value)) return value.map(plain);
  if (value !== null && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, plain(v)]));
  }
  return value;
}

// One MessageReader per ros2msg schema, built from the schema's text as Foxglove builds it.
const cdrReaders = new Map();
function decodeCdr(message, schema) {
  if (!schema || schema.encoding !== "ros2msg") throw new Error(`a cdr message without a ros2msg schema`);
  let reader = cdrReaders.get(schema);
  if (!reader) {
    reader = new MessageReader(parseMessageDefinition(text(schema.data), { ros2: true }));
    cdrReaders.set(schema, reader);
  }
  const value = plain(reader.readMessage(message.data));
  // Every byte read but the padding to a multiple of 4 after the last member.
  if (message.data.byteLength - reader.lastReadByteLength() > 3) throw new Error("CDR bytes left over");
  return value;
}

function messageData(message, channel, schema) {
  if (channel.messageEncoding === "json") return JSON.parse(text(message.data));
  if (channel.messageEncoding === "cdr") return decodeCdr(message, schema);
  return Buffer.from(message.data).toString("hex");
}

function messageJson(message, channel, schema) {
  return {
    topic: channel.topic,
    channelId: message.channelId,
    segment: channel.metadata.get("segment"),
    origin: channel.metadata.get("origin"),
    sequence: message.sequence,
    logTime: String(message.logTime),
    publishTime: String(message.publishTime),
    data: messageData(message, channel, schema),
  };
}

function channelJson(c) {
  return {
    id: c.id,
    topic: c.topic,
    messageEncoding: c.messageEncoding,
    schemaId: c.schemaId,
    metadata: Object.fromEntries(c.metadata),
  };
}

function ordered(messages) {
  return messages.every((m, i) => i === 0 || BigInt(messages[i - 1].logTime) <= BigInt(m.logTime));
}

async function indexed(file, decompressHandlers) {
  const handle = await fs.promises.open(file, "r");
  try {
    const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(handle), decompressHandlers });
    const messages = [];
    for await (const m of reader.readMessages()) {
      const channel = reader.channelsById.get(m.channelId);
      messages.push(messageJson(m, channel, reader.schemasById.get(channel.schemaId)));
    }
    const stats = reader.statistics;
    return {
      profile: reader.header.profile,
      channels: [...reader.channelsById.values()].map(channelJson),
      schemas: [...reader.schemasById.values()].map((s) => ({ id: s.id, name: s.name, encoding: s.encoding, data: text(s.data) })),
      statistics: stats && {
        messageCount: Number(stats.messageCount),
        channelCount: stats.channelCount,
        chunkCount: stats.chunkCount,
        messageStartTime: String(stats.messageStartTime),
        messageEndTime: String(stats.messageEndTime),
      },
      chunkIndexes: reader.chunkIndexes.length,
      metadataIndexes: reader.metadataIndexes.length,
      messages,
      ordered: ordered(messages),
    };
  } finally {
    await handle.close();
  }
}

function stream(file, decompressHandlers) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(fs.readFileSync(file));
  const schemas = new Map();
  const channels = new Map();
  const messages = [];
  for (let record; (record = reader.nextRecord()); ) {
    if (record.type === "Schema") schemas.set(record.id, record);
    if (record.type === "Channel") channels.set(record.id, record);
    if (record.type === "Message") {
      const channel = channels.get(record.channelId);
      messages.push(messageJson(record, channel, schemas.get(channel.schemaId)));
    }
  }
  return { channels: [...channels.values()].map(channelJson), messages, done: reader.done() };
}

async function main() {
  const [mode, file] = process.argv.slice(2);
  const decompressHandlers = await loadDecompressHandlers();
  const out = mode === "indexed" ? await indexed(file, decompressHandlers) : stream(file, decompressHandlers);
  process.stdout.write(JSON.stringify(out) + "\n");
}

// mcap_interop.cjs reads with the same code.
module.exports = { indexed };

if (require.main === module) {
  main().catch((error) => {
    process.stderr.write(`read_recording: ${error.stack || error}\n`);
    process.exit(1);
  });
}
