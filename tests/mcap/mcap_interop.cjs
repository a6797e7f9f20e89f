// cosmic_mcap against the MCAP implementation we did not write (@mcap/core, @mcap/nodejs,
// @mcap/support from npm; tests/mcap/package-lock.json pins them).
//   node mcap_interop.cjs npm-reads-cosmic TOOL WORKDIR
//     TOOL (mcap_sample_tool) writes its deterministic sample and the JSON of what it holds; the
//     npm McapIndexedReader must find the header, schemas, channels, statistics, chunk indexes and
//     metadata, and every message time-ordered with the exact bytes; McapStreamReader over the file
//     cut in the middle of its last chunk must yield every message of the complete chunks.
//   node mcap_interop.cjs cosmic-reads-npm TOOL WORKDIR
//     the npm McapWriter (zstd chunks from @foxglove/wasm-zstd) writes a deterministic file; TOOL
//     dumps what cosmic's reader finds, which must be what was written; the file cut in the middle
//     of its last chunk must give the messages of the complete chunks, marked truncated.
//   node mcap_interop.cjs npm-decodes-cdr TOOL WORKDIR
//     TOOL (mcap_cdr_sample) writes typed events of a type with every kind of field as the recorder
//     does under typed_encoding: cdr, and the values they carry; @foxglove/rosmsg parses the
//     ros2msg schema and @foxglove/rosmsg2-serialization's MessageReader decodes every message
//     (read_recording.cjs) to exactly those values, field by field.
// Run with NODE_PATH naming the node_modules of `npm ci` in this directory (mcap_interop_test.sh).
"use strict";

const assert = require("node:assert/strict");
const { execFileSync } = require("node:child_process");
const fs = require("node:fs");
const path = require("node:path");
const { McapIndexedReader, McapStreamReader, McapWriter } = require("@mcap/core");
const { FileHandleReadable, FileHandleWritable } = require("@mcap/nodejs");
const { loadDecompressHandlers } = require("@mcap/support");
const zstd = require("@foxglove/wasm-zstd");
const { indexed } = require("./read_recording.cjs");

const hex = (bytes) => Buffer.from(bytes).toString("hex");
const mapObject = (map) => Object.fromEntries([...map.entries()].sort());

function messageJson(m) {
  return {
    channelId: m.channelId,
    sequence: m.sequence,
    logTime: String(m.logTime),
    publishTime: String(m.publishTime),
    data: hex(m.data),
  };
}

// The messages McapStreamReader reads from `bytes`, and how many of them the last chunk holds.
function streamMessages(bytes, decompressHandlers) {
  const reader = new McapStreamReader({ decompressHandlers, includeChunks: true, validateCrcs: true });
  reader.append(bytes);
  const messages = [];
  let sinceLastChunk = 0;
  for (let record; (record = reader.nextRecord()); ) {
    if (record.type === "Chunk") sinceLastChunk = 0;
    if (record.type === "Message") {
      messages.push(messageJson(record));
      sinceLastChunk += 1;
    }
  }
  return { messages, lastChunkCount: sinceLastChunk, done: reader.done() };
}

// The file cut in the middle of its last chunk (located by the npm reader's chunk indexes).
async function cutInLastChunk(file, decompressHandlers) {
  const handle = await fs.promises.open(file, "r");
  try {
    const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(handle), decompressHandlers });
    const last = [...reader.chunkIndexes].sort((a, b) => Number(a.chunkStartOffset - b.chunkStartOffset)).at(-1);
    return Number(last.chunkStartOffset + last.chunkLength / 2n);
  } finally {
    await handle.close();
  }
}

async function npmReadsCosmic(tool, work, decompressHandlers) {
  const file = path.join(work, "cosmic.mcap");
  const expectedFile = path.join(work, "cosmic.json");
  execFileSync(tool, ["write", file, expectedFile], { stdio: "inherit" });
  const expected = JSON.parse(fs.readFileSync(expectedFile, "utf8"));

  const handle = await fs.promises.open(file, "r");
  const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(handle), decompressHandlers });
  assert.deepEqual({ profile: reader.header.profile, library: reader.header.library }, expected.header);
  assert.deepEqual(
    [...reader.schemasById.values()].map((s) => ({ id: s.id, name: s.name, encoding: s.encoding, data: hex(s.data) })),
    expected.schemas,
  );
  assert.deepEqual(
    [...reader.channelsById.values()].map((c) => ({
      id: c.id,
      schemaId: c.schemaId,
      topic: c.topic,
      messageEncoding: c.messageEncoding,
      metadata: mapObject(c.metadata),
    })),
    expected.channels,
  );

  // Statistics against the expected messages.
  const stats = reader.statistics;
  assert.ok(stats, "no statistics record");
  const counts = new Map();
  for (const m of expected.messages) counts.set(m.channelId, (counts.get(m.channelId) ?? 0n) + 1n);
  const times = expected.messages.map((m) => BigInt(m.logTime));
  assert.equal(stats.messageCount, BigInt(expected.messages.length));
  assert.deepEqual(mapObject(stats.channelMessageCounts), mapObject(counts));
  assert.equal(stats.schemaCount, 2);
  assert.equal(stats.channelCount, 3);
  assert.equal(stats.metadataCount, 1);
  assert.equal(stats.messageStartTime, times.reduce((a, b) => (b < a ? b : a)));
  assert.equal(stats.messageEndTime, times.reduce((a, b) => (b > a ? b : a)));

  // Chunk indexes: one per chunk, zstd, every channel of a chunk indexed, times within the file's.
  assert.ok(reader.chunkIndexes.length > 10, `only ${reader.chunkIndexes.length} chunks`);
  assert.equal(stats.chunkCount, reader.chunkIndexes.length);
  for (const c of reader.chunkIndexes) {
    assert.equal(c.compression, "zstd");
    assert.ok(c.messageIndexOffsets.size > 0);
    assert.ok(c.messageStartTime <= c.messageEndTime);
    assert.ok(c.compressedSize < c.uncompressedSize);
  }
  for (const opcode of [0x03, 0x04, 0x08, 0x0b]) assert.ok(reader.summaryOffsetsByOpcode.has(opcode), `opcode ${opcode}`);

  // Every message, in log-time order, with its bytes.
  const read = [];
  for await (const m of reader.readMessages({ validateCrcs: true })) read.push(messageJson(m));
  const byTime = [...expected.messages].sort((a, b) => (BigInt(a.logTime) < BigInt(b.logTime) ? -1 : 1));
  assert.notDeepEqual(byTime, expected.messages, "the sample must have messages out of log-time order");
  assert.deepEqual(read, byTime);

  const metadata = [];
  for await (const m of reader.readMetadata()) metadata.push({ name: m.name, metadata: mapObject(m.metadata) });
  assert.deepEqual(metadata, expected.metadata);
  await handle.close();

  // Cut in the middle of the last chunk: every message of the chunks before it, in file order.
  const bytes = fs.readFileSync(file);
  const whole = streamMessages(bytes, decompressHandlers);
  assert.ok(whole.done);
  assert.deepEqual(whole.messages, expected.messages);
  const cut = await cutInLastChunk(file, decompressHandlers);
  const partial = streamMessages(bytes.subarray(0, cut), decompressHandlers);
  assert.ok(!partial.done);
  assert.ok(whole.lastChunkCount > 0);
  assert.deepEqual(partial.messages, expected.messages.slice(0, expected.messages.length - whole.lastChunkCount));
  console.log(
    `npm-reads-cosmic: ${read.length} messages in ${reader.chunkIndexes.length} chunks time-ordered and equal; ` +
      `cut at ${cut} of ${bytes.length} bytes: ${partial.messages.length} messages of the complete chunks`,
  );
}

// Message i of the npm file: channels 0..2 in turn, times not always rising, 0..99 bytes.
function npmMessage(i, channelIds) {
  const channelId = channelIds[i % 3];
  const logTime = 5_000_000_000n + BigInt(i) * 1_000_000n - (i % 5 === 2 ? 2_500_000n : 0n);
  const data = new Uint8Array((i * 13) % 100);
  for (let k = 0; k < data.length; k++) data[k] = (i * 7 + k * 3) & 0xff;
  return { channelId, sequence: i, logTime, publishTime: logTime - 1000n, data };
}

async function cosmicReadsNpm(tool, work) {
  await zstd.isLoaded;
  const file = path.join(work, "npm.mcap");
  const handle = await fs.promises.open(file, "w");
  const writer = new McapWriter({
    writable: new FileHandleWritable(handle),
    chunkSize: 4096,
    compressChunk: (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) }),
  });
  const header = { profile: "x-npm", library: "@mcap/core" };
  await writer.start(header);
  const schemas = [
    { name: "pkg/msg/Pose", encoding: "ros2msg", data: Buffer.from("float64 x\nfloat64 y\n") },
    { name: "Status", encoding: "jsonschema", data: Buffer.from('{"type":"object"}') },
  ];
  const schemaIds = [];
  for (const s of schemas) schemaIds.push(await writer.registerSchema(s));
  const channels = [
    { schemaId: schemaIds[0], topic: "/pose", messageEncoding: "cdr", metadata: new Map([["a", "1"]]) },
    { schemaId: schemaIds[1], topic: "/status", messageEncoding: "json", metadata: new Map() },
    { schemaId: 0, topic: "/raw", messageEncoding: "x-raw", metadata: new Map([["z", "last"], ["b", "2"]]) },
  ];
  const channelIds = [];
  for (const c of channels) channelIds.push(await writer.registerChannel(c));
  const messages = [];
  for (let i = 0; i < 2500; i++) {
    if (i === 1000) await writer.addMetadata({ name: "run", metadata: new Map([["robot", "r1"]]) });
    const m = npmMessage(i, channelIds);
    messages.push(messageJson(m));
    await writer.addMessage(m);
  }
  await writer.end();
  await handle.close();

  const dump = (f) => JSON.parse(execFileSync(tool, ["dump", f], { encoding: "utf8", maxBuffer: 1 << 28 }));
  const read = dump(file);
  assert.deepEqual(read.header, header);
  assert.deepEqual(
    read.schemas,
    schemas.map((s, i) => ({ id: schemaIds[i], name: s.name, encoding: s.encoding, data: hex(s.data) })),
  );
  assert.deepEqual(
    [...read.channels].sort((a, b) => a.id - b.id),
    channels.map((c, i) => ({
      id: channelIds[i],
      schemaId: c.schemaId,
      topic: c.topic,
      messageEncoding: c.messageEncoding,
      metadata: mapObject(c.metadata),
    })),
  );
  assert.deepEqual(read.metadata, [{ name: "run", metadata: { robot: "r1" } }]);
  assert.equal(read.truncated, false, read.truncation);
  assert.equal(read.statisticsMessageCount, messages.length);
  assert.deepEqual(read.messages, messages);

  const decompressHandlers = await loadDecompressHandlers();
  const bytes = fs.readFileSync(file);
  const whole = streamMessages(bytes, decompressHandlers);
  const cut = await cutInLastChunk(file, decompressHandlers);
  const cutFile = path.join(work, "npm-cut.mcap");
  fs.writeFileSync(cutFile, bytes.subarray(0, cut));
  const partial = dump(cutFile);
  assert.equal(partial.truncated, true);
  assert.ok(whole.lastChunkCount > 0);
  assert.deepEqual(partial.messages, messages.slice(0, messages.length - whole.lastChunkCount));
  console.log(
    `cosmic-reads-npm: ${read.messages.length} messages of the npm writer read back equal; cut at ${cut} of ` +
      `${bytes.length} bytes: ${partial.messages.length} messages, truncated (${partial.truncation})`,
  );
}

async function npmDecodesCdr(tool, work, decompressHandlers) {
  const file = path.join(work, "cdr.mcap");
  const expectedFile = path.join(work, "cdr.json");
  execFileSync(tool, [file, expectedFile], { stdio: "inherit" });
  const expected = JSON.parse(fs.readFileSync(expectedFile, "utf8"));
  const read = await indexed(file, decompressHandlers);
  assert.deepEqual(
    read.schemas.map((s) => [s.name, s.encoding]),
    [[expected.schemaName, "ros2msg"]],
  );
  assert.deepEqual(
    read.channels.map((c) => c.messageEncoding),
    ["cdr"],
  );
  assert.equal(read.messages.length, expected.values.length);
  read.messages.forEach((m, i) => {
    for (const [name, value] of Object.entries(expected.values[i]))
      assert.deepEqual(m.data[name], value, `message ${i + 1}, field ${name}`);
    assert.deepEqual(Object.keys(m.data), Object.keys(expected.values[i]), `message ${i + 1}: the fields in order`);
  });
  console.log(
    `npm-decodes-cdr: ${read.messages.length} messages of ${expected.schemaName} decoded by ` +
      `@foxglove/rosmsg2-serialization to the values sent, ${Object.keys(expected.values[0]).length} fields each`,
  );
}

async function main() {
  const [mode, tool, work] = process.argv.slice(2);
  if (!mode || !tool || !work) throw new Error("usage: mcap_interop.cjs npm-reads-cosmic|cosmic-reads-npm|npm-decodes-cdr TOOL WORKDIR");
  fs.mkdirSync(work, { recursive: true });
  if (mode === "npm-reads-cosmic") return npmReadsCosmic(tool, work, await loadDecompressHandlers());
  if (mode === "cosmic-reads-npm") return cosmicReadsNpm(tool, work);
  if (mode === "npm-decodes-cdr") return npmDecodesCdr(tool, work, await loadDecompressHandlers());
  throw new Error(`unknown mode ${mode}`);
}

main().catch((error) => {
  console.error(error);
  process.exit(1);
});
