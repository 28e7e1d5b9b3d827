// The other direction (tests/recording/interop.sh): the reference MCAP writer (@mcap/core) writes
// a file that mapless then reads.   node rewrite.mjs IN.mcap OUT.mcap
// Every schema, channel and message of IN is written again by @mcap/core's McapWriter, in its own
// layout: chunks of 64 KiB compressed with zstd (wasm-zstd), its own indexes and summary.
import zstd from "@foxglove/wasm-zstd";
import { McapIndexedReader, McapWriter, TempBuffer } from "@mcap/core";
import fs from "node:fs";

await zstd.isLoaded;
const [input, output] = process.argv.slice(2);
const bytes = new Uint8Array(fs.readFileSync(input));
const reader = await McapIndexedReader.Initialize({
  readable: new TempBuffer(bytes),
  decompressHandlers: { zstd: (b, size) => zstd.decompress(b, Number(size)) },
});
const out = new TempBuffer();
const writer = new McapWriter({
  writable: out,
  chunkSize: 64 * 1024,
  compressChunk: (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) }),
});
await writer.start({ profile: "ros2", library: "@mcap/core (mapless interop test)" });
const schemaIds = new Map();
for (const s of reader.schemasById.values()) {
  schemaIds.set(s.id, await writer.registerSchema({ name: s.name, encoding: s.encoding, data: s.data }));
}
const channelIds = new Map();
for (const c of reader.channelsById.values()) {
  channelIds.set(c.id, await writer.registerChannel({
    topic: c.topic, schemaId: schemaIds.get(c.schemaId), messageEncoding: c.messageEncoding,
    metadata: c.metadata,
  }));
}
let n = 0;
for await (const m of reader.readMessages()) {
  await writer.addMessage({ ...m, channelId: channelIds.get(m.channelId) });
  n += 1;
}
await writer.end();
fs.writeFileSync(output, out.get(), { flag: "wx" });
console.log(`ok   ${output}: ${n} messages written by @mcap/core`);
