// The reference MCAP reader against mapless's recordings (tests/recording/interop.sh, issue 20).
//   node decode.mjs FILE.mcap...
// For each file, twice:
//  - streamed: @mcap/core's McapStreamReader reads every record from the magic to the footer, with
//    CRCs checked and chunks (zstd, lz4 or none) opened, and counts each kind;
//  - indexed: McapIndexedReader seeks through the summary and chunk indexes and reads every
//    message, which is decoded from its schema: ROS 2 CDR with Foxglove's reader against the
//    schema's own definition (ros2msg), JSON for the decisions.
// Every message must decode; the two reads must agree with each other and with the statistics;
// each topic's values must be what the topic means (image sizes, frames, quaternions).
// Prints a line per file; exit 0 when every file passes.
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import decompressLZ4 from "@foxglove/wasm-lz4";
import zstd from "@foxglove/wasm-zstd";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import fs from "node:fs";

await decompressLZ4.isLoaded;
await zstd.isLoaded;
const decompressHandlers = {
  lz4: (buffer, size) => decompressLZ4(buffer, Number(size)),
  zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
};

let failures = 0;
const fail = (file, why) => {
  console.log(`FAIL ${file}: ${why}`);
  failures += 1;
};

const streamed = (bytes) => {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true, includeChunks: true });
  reader.append(bytes);
  const kinds = {};
  const messages = [];
  for (let record; (record = reader.nextRecord()); ) {
    kinds[record.type] = (kinds[record.type] ?? 0) + 1;
    if (record.type === "Message") messages.push(`${record.channelId}:${record.sequence}:${record.logTime}`);
  }
  if (!reader.done()) throw new Error(`${reader.bytesRemaining()} bytes left after the last record`);
  return { kinds, messages };
};

// What each topic must hold, beyond decoding.
const checks = {
  "sensor_msgs/msg/Image": (m) =>
    m.encoding === "mono8" && m.data.length === m.width * m.height && m.step === m.width &&
    m.header.frame_id === "camera",
  "sensor_msgs/msg/CompressedImage": (m) =>
    ((m.format === "png" && m.data[0] === 0x89 && m.data[1] === 0x50) ||
     (m.format === "jpeg" && m.data[0] === 0xff && m.data[1] === 0xd8)) &&
    m.header.frame_id === "camera",
  "sensor_msgs/msg/CameraInfo": (m) =>
    m.k.length === 9 && m.p.length === 12 && m.k[8] === 1 && m.width > 0 &&
    m.distortion_model === "plumb_bob",
  "geometry_msgs/msg/Twist": (m) =>
    Number.isFinite(m.linear.x) && Number.isFinite(m.angular.z) && m.linear.y === 0,
  "nav_msgs/msg/Odometry": (m) =>
    m.header.frame_id === "odom" && m.child_frame_id === "base_link" &&
    Math.abs(Math.hypot(m.pose.pose.orientation.z, m.pose.pose.orientation.w) - 1) < 1e-9 &&
    m.pose.covariance.length === 36,
  "geometry_msgs/msg/PoseStamped": (m) =>
    m.header.frame_id === "world" &&
    Math.abs(Math.hypot(m.pose.orientation.z, m.pose.orientation.w) - 1) < 1e-9,
  "mapless/Decision": (m) =>
    typeof m.state === "string" && typeof m.method === "string" && Number.isFinite(m.v_mps),
};

for (const file of process.argv.slice(2)) {
  try {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const s = streamed(bytes);
    for (const kind of ["Header", "Schema", "Channel", "Chunk", "Message", "MessageIndex",
                        "DataEnd", "Statistics", "ChunkIndex", "SummaryOffset", "Footer"]) {
      if (!s.kinds[kind]) throw new Error(`no ${kind} record`);
    }
    const readable = {
      size: async () => BigInt(bytes.length),
      read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
    };
    const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    const readers = new Map();
    const counts = {};
    const seen = [];
    let last = -1n;
    for await (const m of indexed.readMessages()) {
      const channel = indexed.channelsById.get(m.channelId);
      const schema = indexed.schemasById.get(channel.schemaId);
      let value;
      if (channel.messageEncoding === "cdr" && schema.encoding === "ros2msg") {
        if (!readers.has(schema.id)) {
          const text = new TextDecoder().decode(schema.data);
          readers.set(schema.id, new MessageReader(parse(text, { ros2: true })));
        }
        value = readers.get(schema.id).readMessage(m.data);
      } else if (channel.messageEncoding === "json" && schema.encoding === "jsonschema") {
        JSON.parse(new TextDecoder().decode(schema.data));
        value = JSON.parse(new TextDecoder().decode(m.data));
      } else {
        throw new Error(`${channel.topic}: unexpected encodings ${channel.messageEncoding}/${schema.encoding}`);
      }
      const check = checks[schema.name];
      if (!check) throw new Error(`${channel.topic}: unexpected schema ${schema.name}`);
      if (!check(value)) throw new Error(`${channel.topic} message ${m.sequence}: ${JSON.stringify(value).slice(0, 200)}`);
      if (m.logTime < last) throw new Error(`${channel.topic}: log time goes back`);
      last = m.logTime;
      counts[channel.topic] = (counts[channel.topic] ?? 0) + 1;
      seen.push(`${m.channelId}:${m.sequence}:${m.logTime}`);
    }
    const stats = indexed.statistics;
    if (BigInt(seen.length) !== stats.messageCount)
      throw new Error(`read ${seen.length} messages, the statistics say ${stats.messageCount}`);
    if (seen.join() !== s.messages.join()) throw new Error("the streamed and indexed reads differ");
    const compression = [...new Set(indexed.chunkIndexes.map((c) => c.compression || "none"))].join(",");
    const topics = Object.entries(counts).map(([t, n]) => `${t} ${n}`).join(", ");
    console.log(`ok   ${file}: ${seen.length} messages in ${s.kinds.Chunk} chunks (${compression}), every record read (${Object.keys(s.kinds).length} kinds); ${topics}`);
  } catch (e) {
    fail(file, e.message);
  }
}
process.exit(failures === 0 ? 0 : 1);
