// node read_mcap.mjs FILE TOPIC...: reads the MCAP that mcap-record wrote with @mcap/core (the
// indexed reader: summary, chunk indexes, every message) and checks each TOPIC has messages.
import { McapIndexedReader } from "@mcap/core";
import * as Zstd from "@foxglove/wasm-zstd";
import { open } from "node:fs/promises";

const [file, ...topics] = process.argv.slice(2);
await Zstd.isLoaded;
const handle = await open(file, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, length) => {
    const buffer = new Uint8Array(Number(length));
    await handle.read(buffer, 0, Number(length), Number(offset));
    return buffer;
  },
};
const reader = await McapIndexedReader.Initialize({
  readable,
  decompressHandlers: { zstd: (data, size) => Zstd.decompress(data, Number(size)) },
});
const counts = {};
for (const channel of reader.channelsById.values()) counts[channel.topic] = 0;
for await (const message of reader.readMessages()) {
  const channel = reader.channelsById.get(message.channelId);
  counts[channel.topic] += 1;
}
await handle.close();
const missing = topics.filter((t) => !counts[t]);
console.log(JSON.stringify({ file, counts, missing }));
process.exit(missing.length ? 1 : 0);
