// SPDX-License-Identifier: MIT
// Reads an MCAP file with the MCAP project's own indexed reader (@mcap/core, by its summary
// and chunk indexes, zstd/lz4 through @mcap/support) and decodes every message with the
// Foxglove ROS 2 deserialiser (@foxglove/rosmsg + @foxglove/rosmsg2-serialization), then
// prints what it found as JSON on stdout, for tests/mcap to compare with what Binocle wrote:
//   {header: {profile, library}, statistics: {...}, chunks: N, chunk_compressions: [...],
//    channels: [{id, topic, message_encoding, schema_name, schema_encoding}],
//    messages: [{topic, log_time, publish_time, sequence, value}]}
// Byte arrays (uint8[]: image and cloud data) become {length, crc32}.
// usage: node read_reference.cjs FILE.mcap
"use strict";
const fs = require("fs");

// CRC-32 (zlib's): the digest of byte arrays, compared with binocle::mcap::crc32.
const crcTable = (() => {
  const t = new Uint32Array(256);
  for (let i = 0; i < 256; ++i) {
    let c = i;
    for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[i] = c >>> 0;
  }
  return t;
})();
function crc32(bytes) {
  let c = 0xffffffff;
  for (let i = 0; i < bytes.length; ++i) c = crcTable[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}
const { McapIndexedReader } = require("@mcap/core");
const { loadDecompressHandlers } = require("@mcap/support");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");

function plain(value) {
  if (value instanceof Uint8Array) return { length: value.length, crc32: crc32(value) };
  if (ArrayBuffer.isView(value)) return Array.from(value); // float64[] (CameraInfo d, k ...)
  if (typeof value === "bigint") return value.toString();
  if (Array.isArray(value)) return value.map(plain);
  if (value && typeof value === "object") {
    const out = {};
    for (const [k, v] of Object.entries(value)) out[k] = plain(v);
    return out;
  }
  return value;
}

async function main() {
  const path = process.argv[2];
  const handle = await fs.promises.open(path, "r");
  const size = BigInt((await handle.stat()).size);
  const readable = {
    size: async () => size,
    read: async (offset, length) => {
      const buf = Buffer.alloc(Number(length));
      const { bytesRead } = await handle.read(buf, 0, Number(length), Number(offset));
      if (bytesRead !== Number(length)) throw new Error(`short read at ${offset}`);
      return new Uint8Array(buf.buffer, buf.byteOffset, bytesRead);
    },
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers: await loadDecompressHandlers() });
  const decoders = new Map();
  const channels = [];
  for (const [id, ch] of reader.channelsById) {
    const schema = reader.schemasById.get(ch.schemaId);
    channels.push({
      id, topic: ch.topic, message_encoding: ch.messageEncoding,
      schema_name: schema ? schema.name : null, schema_encoding: schema ? schema.encoding : null,
      metadata: Object.fromEntries(ch.metadata),
    });
    if (schema && schema.encoding === "ros2msg" && ch.messageEncoding === "cdr") {
      const defs = parse(new TextDecoder().decode(schema.data), { ros2: true });
      decoders.set(id, new MessageReader(defs));
    }
  }
  const messages = [];
  for await (const m of reader.readMessages()) {
    const decoder = decoders.get(m.channelId);
    if (!decoder) throw new Error(`channel ${m.channelId} has no ros2msg/cdr schema`);
    messages.push({
      topic: reader.channelsById.get(m.channelId).topic,
      log_time: m.logTime.toString(), publish_time: m.publishTime.toString(), sequence: m.sequence,
      value: plain(decoder.readMessage(m.data)),
    });
  }
  const s = reader.statistics;
  const out = {
    header: reader.header,
    statistics: s ? {
      message_count: s.messageCount.toString(), chunk_count: s.chunkCount, channel_count: s.channelCount,
      schema_count: s.schemaCount, message_start_time: s.messageStartTime.toString(),
      message_end_time: s.messageEndTime.toString(),
    } : null,
    chunks: reader.chunkIndexes.length,
    chunk_compressions: [...new Set(reader.chunkIndexes.map((c) => c.compression))],
    data_section_crc: reader.dataSectionCrc ?? null,
    channels, messages,
  };
  await handle.close();
  process.stdout.write(JSON.stringify(out));
}

main().catch((e) => {
  process.stderr.write(`read_reference: ${e.stack || e}\n`);
  process.exit(1);
});
