// node watch.mjs URL SUBPROTOCOL SECONDS: connects to mapless's live view with Foxglove's client
// under SUBPROTOCOL, checks the server's answer, subscribes to every channel advertised and
// decodes every message until the server closes (or SECONDS pass). Prints one JSON summary line;
// exits 1 when anything failed.
import wsProtocol from "@foxglove/ws-protocol";
import { parse as parseMessageDefinition } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";

const { FoxgloveClient } = wsProtocol;
import Ajv from "ajv";
import { WebSocket } from "ws";

const [url, subprotocol, seconds] = process.argv.slice(2);
const failures = [];
const fail = (what) => { if (failures.length < 20) failures.push(what); };
const ajv = new Ajv({ strict: false });
const channels = new Map();  // subscription id -> {channel, decode, count}
const summary = { subprotocol: null, serverInfo: null, channels: 0, messages: {}, times: 0 };

const ws = new WebSocket(url, [subprotocol]);
const client = new FoxgloveClient({ ws });
const timer = setTimeout(() => { fail(`still open after ${seconds} s`); client.close(); }, seconds * 1000);

ws.on("open", () => { summary.subprotocol = ws.protocol; });
client.on("serverInfo", (info) => {
  summary.serverInfo = info;
  if (info.capabilities.some((c) => ["clientPublish", "services", "parameters"].includes(c)))
    fail(`the server offers ${info.capabilities}: it must be read-only`);
});
client.on("status", (s) => { if (s.level >= 2) fail(`status: ${s.message}`); });
client.on("error", (e) => fail(`error: ${e}`));
client.on("advertise", (advertised) => {
  for (const channel of advertised) {
    let decode;
    if (channel.encoding === "cdr" && channel.schemaEncoding === "ros2msg") {
      const reader = new MessageReader(parseMessageDefinition(channel.schema, { ros2: true }));
      decode = (data) => reader.readMessage(data);
    } else if (channel.encoding === "json" && channel.schemaEncoding === "jsonschema") {
      const validate = ajv.compile(JSON.parse(channel.schema));
      decode = (data) => {
        const value = JSON.parse(new TextDecoder().decode(data));
        if (!validate(value)) throw new Error(ajv.errorsText(validate.errors));
        return value;
      };
    } else {
      fail(`${channel.topic}: encoding ${channel.encoding} / ${channel.schemaEncoding}`);
      continue;
    }
    const id = client.subscribe(channel.id);
    channels.set(id, { channel, decode });
    summary.messages[channel.topic] = 0;
    summary.channels += 1;
  }
});
client.on("time", () => { summary.times += 1; });
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const sub = channels.get(subscriptionId);
  if (!sub) return fail(`a message for subscription ${subscriptionId}, never made`);
  try {
    const m = sub.decode(data);
    if (sub.channel.topic.endsWith("/compressed")) {
      if (m.format !== "jpeg" || m.data[0] !== 0xff || m.data[1] !== 0xd8) throw new Error("not a JPEG");
      const stamp = BigInt(m.header.stamp.sec) * 1000000000n + BigInt(m.header.stamp.nanosec);
      if (stamp !== timestamp) throw new Error(`stamp ${stamp} is not the message's time ${timestamp}`);
    }
    if (sub.channel.topic === "/mapless/decision" && !["driving", "stopped", "finished", "failed"].includes(m.state))
      throw new Error(`state ${m.state}`);
    summary.messages[sub.channel.topic] += 1;
  } catch (e) {
    fail(`${sub.channel.topic}: ${e.message}`);
  }
});
client.on("close", () => {
  clearTimeout(timer);
  if (summary.subprotocol !== subprotocol) fail(`the server answered ${summary.subprotocol}, not ${subprotocol}`);
  if (!summary.serverInfo) fail("no serverInfo");
  for (const [topic, n] of Object.entries(summary.messages)) if (n === 0) fail(`nothing on ${topic}`);
  if (summary.channels === 0) fail("no channel advertised");
  console.log(JSON.stringify({ ...summary, serverInfo: summary.serverInfo?.name, failures }));
  process.exit(failures.length ? 1 : 0);
});
