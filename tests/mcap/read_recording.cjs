// What the MCAP implementation we did not write (npm's @mcap/core, @mcap/nodejs, @mcap/support)
// reads of a file cosmicd recorded, as JSON on standard output for the tests to check.
//   node read_recording.cjs indexed FILE
//     McapIndexedReader (summary, chunk indexes, statistics): channels, schemas, statistics, the
//     number of chunk indexes, and every message in log-time order with its topic (a `json`
//     message parsed, others as hex); `ordered` says whether the log times never went back.
//   node read_recording.cjs stream FILE
//     McapStreamReader over the bytes as they are (a file cut short by a crash): the channels and
//     messages of every complete record, and whether the reader reached the end of a whole file.
// Run with NODE_PATH naming the node_modules of tests/mcap's `npm ci`.
"use strict";

const fs = require("node:fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { FileHandleReadable } = require("@mcap/nodejs");
const { loadDecompressHandlers } = require("@mcap/support");

const text = (bytes) => Buffer.from(bytes).toString("utf8");

function messageJson(message, channel) {
  return {
    topic: channel.topic,
    channelId: message.channelId,
    segment: channel.metadata.get("segment"),
    origin: channel.metadata.get("origin"),
    sequence: message.sequence,
    logTime: String(message.logTime),
    publishTime: String(message.publishTime),
    data: channel.messageEncoding === "json" ? JSON.parse(text(message.data)) : Buffer.from(message.data).toString("hex"),
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
    for await (const m of reader.readMessages()) messages.push(messageJson(m, reader.channelsById.get(m.channelId)));
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
  const channels = new Map();
  const messages = [];
  for (let record; (record = reader.nextRecord()); ) {
    if (record.type === "Channel") channels.set(record.id, record);
    if (record.type === "Message") messages.push(messageJson(record, channels.get(record.channelId)));
  }
  return { channels: [...channels.values()].map(channelJson), messages, done: reader.done() };
}

async function main() {
  const [mode, file] = process.argv.slice(2);
  const decompressHandlers = await loadDecompressHandlers();
  const out = mode === "indexed" ? await indexed(file, decompressHandlers) : stream(file, decompressHandlers);
  process.stdout.write(JSON.stringify(out) + "\n");
}

main().catch((error) => {
  process.stderr.write(`read_recording: ${error.stack || error}\n`);
  process.exit(1);
});
