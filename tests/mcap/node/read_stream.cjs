// SPDX-License-Identifier: MIT
// Reads an MCAP file front to back with the MCAP project's own stream reader
// (@mcap/core McapStreamReader, chunks decompressed through @mcap/support), as a reader of
// a file cut short does (no summary needed), and prints what it recovered as JSON:
//   {complete: bool (a footer was reached), messages: N, by_topic: {topic: N}, error: text|null}
// Reading stops at the first record that is incomplete or fails its checks.
// usage: node read_stream.cjs FILE.mcap
"use strict";
const fs = require("fs");
const { McapStreamReader } = require("@mcap/core");
const { loadDecompressHandlers } = require("@mcap/support");

async function main() {
  const reader = new McapStreamReader({ decompressHandlers: await loadDecompressHandlers() });
  reader.append(new Uint8Array(fs.readFileSync(process.argv[2])));
  const topics = new Map();
  const byTopic = {};
  let messages = 0;
  let error = null;
  try {
    for (let r; (r = reader.nextRecord());) {
      if (r.type === "Channel") topics.set(r.id, r.topic);
      if (r.type === "Message") {
        const t = topics.get(r.channelId) ?? `#${r.channelId}`;
        byTopic[t] = (byTopic[t] ?? 0) + 1;
        ++messages;
      }
    }
  } catch (e) {
    error = String(e.message || e);
  }
  process.stdout.write(JSON.stringify({ complete: reader.done(), messages, by_topic: byTopic, error }));
}

main().catch((e) => {
  process.stderr.write(`read_stream: ${e.stack || e}\n`);
  process.exit(1);
});
