// SPDX-License-Identifier: MIT
// Writes a rosbag2-style MCAP bag with the MCAP project's own writer (@mcap/core) and the
// Foxglove ROS 2 serialiser, for tests/mcap and tests/plugins_replay to read back:
// two mono8 image topics /stereo/left/image_raw and /stereo/right/image_raw plus their
// camera_info, FRAMES pairs of WIDTHxHEIGHT. The left image is a texture of pseudo-random
// values (xorshift32 seeded per frame, the same generator as tests/mcap/reference_scene.hpp);
// the right image is the left one shifted by DISPARITY pixels: right(x) = left(x + d),
// so a matcher must find the constant disparity d. Stamps: frame i at 1.7e9 s + i * 50 ms;
// right stamps 1 ms later than the left ones (pairing tolerance).
// usage: node write_reference.cjs OUT.mcap [--compression zstd|lz4|none] [--no-chunk-index]
//        [--no-chunks] [--frames N] [--width W] [--height H] [--disparity D] [--encoding mono8|rgb8|mono16]
"use strict";
const fs = require("fs");
const { McapWriter } = require("@mcap/core");
const { parse } = require("@foxglove/rosmsg");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");

const defs = {
  image: `std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
`,
  info: `std_msgs/Header header
uint32 height
uint32 width
string distortion_model
float64[] d
float64[9] k
float64[9] r
float64[12] p
uint32 binning_x
uint32 binning_y
RegionOfInterest roi
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
================================================================================
MSG: sensor_msgs/RegionOfInterest
uint32 x_offset
uint32 y_offset
uint32 height
uint32 width
bool do_rectify
`,
};

function arg(name, fallback) {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : fallback;
}

// xorshift32: the texture of frame `frame` (tests/mcap/reference_scene.hpp).
function texture(width, height, frame) {
  let s = (0x9e3779b9 ^ (frame * 0x85ebca6b)) >>> 0 || 1;
  const out = new Uint8Array(width * height);
  for (let i = 0; i < out.length; ++i) {
    s ^= s << 13; s >>>= 0;
    s ^= s >>> 17;
    s ^= s << 5; s >>>= 0;
    out[i] = s & 0xff;
  }
  return out;
}

async function main() {
  const out = process.argv[2];
  const compression = arg("--compression", "zstd");
  const frames = Number(arg("--frames", "5"));
  const width = Number(arg("--width", "64"));
  const height = Number(arg("--height", "48"));
  const d = Number(arg("--disparity", "8"));
  const encoding = arg("--encoding", "mono8");
  const channelsPerPixel = encoding === "rgb8" ? 3 : 1;
  const bytesPerChannel = encoding === "mono16" ? 2 : 1;
  let compressChunk;
  if (compression === "zstd") {
    const zstd = require("@foxglove/wasm-zstd");
    await zstd.isLoaded;
    compressChunk = (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) });
  } else if (compression !== "none") {
    throw new Error(`--compression ${compression}: expected zstd or none (the reference package compresses only zstd)`);
  }
  const handle = await fs.promises.open(out, "wx");
  const writable = {
    position: 0n,
    async write(buffer) {
      await handle.write(buffer);
      this.position += BigInt(buffer.byteLength);
    },
  };
  const writer = new McapWriter({
    writable: { write: (b) => writable.write(b), position: () => writable.position },
    useChunks: !process.argv.includes("--no-chunks"),
    useChunkIndex: !process.argv.includes("--no-chunk-index"),
    chunkSize: 32 * 1024,
    compressChunk,
  });
  await writer.start({ profile: "ros2", library: "mcap-js reference writer (tests/mcap)" });
  const imageSchema = await writer.registerSchema({ name: "sensor_msgs/msg/Image", encoding: "ros2msg",
    data: new TextEncoder().encode(defs.image) });
  const infoSchema = await writer.registerSchema({ name: "sensor_msgs/msg/CameraInfo", encoding: "ros2msg",
    data: new TextEncoder().encode(defs.info) });
  const imageWriter = new MessageWriter(parse(defs.image, { ros2: true }));
  const infoWriter = new MessageWriter(parse(defs.info, { ros2: true }));
  const ch = {};
  for (const side of ["left", "right"]) {
    ch[side] = await writer.registerChannel({ schemaId: imageSchema, topic: `/stereo/${side}/image_raw`,
      messageEncoding: "cdr", metadata: new Map([["offered_qos_profiles", ""]]) });
    ch[side + "_info"] = await writer.registerChannel({ schemaId: infoSchema, topic: `/stereo/${side}/camera_info`,
      messageEncoding: "cdr", metadata: new Map() });
  }
  const f = 100, cx = (width - 1) / 2, cy = (height - 1) / 2, baselineM = 0.12;
  for (let i = 0; i < frames; ++i) {
    const base = 1700000000n * 1000000000n + BigInt(i) * 50000000n;
    const tex = texture(width + d, height, i); // d extra columns so right(x) = left(x + d) everywhere
    for (const side of ["left", "right"]) {
      const t = side === "left" ? base : base + 1000000n;
      const stamp = { sec: Number(t / 1000000000n), nanosec: Number(t % 1000000000n) };
      const header = { stamp, frame_id: `stereo_${side}_optical` };
      const step = width * channelsPerPixel * bytesPerChannel;
      const data = new Uint8Array(step * height);
      for (let y = 0; y < height; ++y)
        for (let x = 0; x < width; ++x) {
          // left(x) = tex(x), right(x) = tex(x + d) = left(x + d): the left pixel x is
          // seen at x - d on the right, a disparity of d.
          const v = tex[y * (width + d) + (side === "left" ? x : x + d)];
          for (let c = 0; c < channelsPerPixel; ++c) {
            const at = y * step + (x * channelsPerPixel + c) * bytesPerChannel;
            if (bytesPerChannel === 2) { data[at] = 0; data[at + 1] = v; } // little-endian v * 256
            else data[at] = v;
          }
        }
      const image = { header, height, width, encoding, is_bigendian: 0, step, data };
      await writer.addMessage({ channelId: ch[side], sequence: i, logTime: t, publishTime: t,
        data: imageWriter.writeMessage(image) });
      const tx = side === "left" ? 0 : -f * baselineM;
      const info = { header, height, width, distortion_model: "plumb_bob", d: [0, 0, 0, 0, 0],
        k: [f, 0, cx, 0, f, cy, 0, 0, 1], r: [1, 0, 0, 0, 1, 0, 0, 0, 1],
        p: [f, 0, cx, tx, 0, f, cy, 0, 0, 0, 1, 0], binning_x: 0, binning_y: 0,
        roi: { x_offset: 0, y_offset: 0, height: 0, width: 0, do_rectify: false } };
      await writer.addMessage({ channelId: ch[side + "_info"], sequence: i, logTime: t, publishTime: t,
        data: infoWriter.writeMessage(info) });
    }
  }
  await writer.end();
  await handle.close();
}

main().catch((e) => {
  process.stderr.write(`write_reference: ${e.stack || e}\n`);
  process.exit(1);
});
