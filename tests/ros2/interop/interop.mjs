// Foxglove's ROS 2 CDR reader and writer against mapless (tests/ros2/interop.sh, issue 18).
//   node interop.mjs read DIR    decode every DIR/NAME.cdr mapless wrote; compare field by field
//                                with DIR/NAME.json and with the values mapless was told to write
//   node interop.mjs write DIR   encode the messages mapless reads: DIR/NAME.in.cdr and
//                                DIR/NAME.in.expected.json
//   node interop.mjs check DIR   compare mapless's decoding (DIR/NAME.in.decoded.json) with
//                                DIR/NAME.in.expected.json
// Prints one line per message; exit 0 when all agree.
import { parse } from "@foxglove/rosmsg";
import { MessageReader, MessageWriter } from "@foxglove/rosmsg2-serialization";
import fs from "node:fs";
import path from "node:path";
import { DEFINITIONS } from "./definitions.mjs";

const [mode, dir] = process.argv.slice(2);
let failures = 0;
const say = (ok, text) => {
  console.log(`${ok ? "ok  " : "FAIL"} ${text}`);
  if (!ok) failures += 1;
};

// Plain values: typed arrays to arrays, so that deep comparison sees numbers.
const plain = (v) => {
  if (ArrayBuffer.isView(v)) return Array.from(v);
  if (Array.isArray(v)) return v.map(plain);
  if (v && typeof v === "object") {
    return Object.fromEntries(Object.keys(v).sort().map((k) => [k, plain(v[k])]));
  }
  return v;
};
const diff = (a, b, where = "") => {
  if (typeof a !== typeof b) return `${where}: ${JSON.stringify(a)} vs ${JSON.stringify(b)}`;
  if (a && typeof a === "object") {
    const keys = new Set([...Object.keys(a), ...Object.keys(b)]);
    for (const k of keys) {
      if (!(k in a) || !(k in b)) return `${where}.${k}: present on one side only`;
      const d = diff(a[k], b[k], `${where}.${k}`);
      if (d) return d;
    }
    return "";
  }
  return a === b ? "" : `${where}: ${JSON.stringify(a)} vs ${JSON.stringify(b)}`;
};
const definition = (type) => parse(DEFINITIONS[type], { ros2: true });
// The fields of every type in a definition, as "type name" lines (to compare two definitions).
const shape = (defs) =>
  defs
    .map((d) => `${d.name ?? ""}{${d.definitions.filter((f) => !f.isConstant).map((f) =>
      `${f.type}${f.isArray ? `[${f.arrayLength ?? ""}]` : ""} ${f.name}`).join(";")}}`)
    .sort()
    .join("\n");

// What mapless was told to write (tests/ros2/cdr_tool.cc), checked independently of both decoders.
const STAMP = { sec: 1732454400, nanosec: 123456789 };
const KNOWN = {
  twist: (m) => m.linear.x === 0.25 && m.angular.z === -0.5 && m.linear.y === 0,
  string: (m) => m.data === '{"method":"repeat","frame":7,"status":"driving – ok"}',
  bool: (m) => m.data === true,
  clock: (m) => !diff(plain(m.clock), STAMP),
  odometry: (m) =>
    !diff(plain(m.header.stamp), STAMP) && m.header.frame_id === "odom" &&
    m.child_frame_id === "base_link" && m.pose.pose.position.x === 1.5 &&
    m.pose.pose.position.y === -2.25 &&
    Math.abs(m.pose.pose.orientation.z - Math.sin(0.375)) < 1e-15 &&
    Math.abs(m.pose.pose.orientation.w - Math.cos(0.375)) < 1e-15 &&
    m.pose.covariance.length === 36,
  image: (m) =>
    m.encoding === "mono8" && m.width === 4 && m.height === 3 && m.step === 4 &&
    m.is_bigendian === 0 && m.data.length === 12 && m.data[0] === 3 && m.data[11] === 234 &&
    m.header.frame_id === "camera" && !diff(plain(m.header.stamp), STAMP),
  compressed_image: (m) =>
    m.format === "jpeg" && m.data.length === 12 && m.data[0] === 0xff && m.data[1] === 0xd8,
};

const names = (suffix) =>
  fs.readdirSync(dir).filter((f) => f.endsWith(suffix)).map((f) => f.slice(0, -suffix.length)).sort();

if (mode === "read") {
  for (const name of names(".type")) {
    const type = fs.readFileSync(path.join(dir, `${name}.type`), "utf8").trim();
    if (!DEFINITIONS[type]) { say(false, `${name}: no ROS 2 definition for ${type}`); continue; }
    // mapless's definition of the type has the same fields as ROS 2's.
    const mine = parse(fs.readFileSync(path.join(dir, `${name}.msg`), "utf8"), { ros2: true });
    const d1 = shape(definition(type)), d2 = shape(mine);
    say(d1 === d2, `${name}: mapless's ${type} definition ${d1 === d2 ? "matches ROS 2's" : `differs:\n${d2}\nvs\n${d1}`}`);
    const bytes = fs.readFileSync(path.join(dir, `${name}.cdr`));
    let message;
    try {
      message = new MessageReader(definition(type)).readMessage(bytes);
    } catch (e) {
      say(false, `${name}: Foxglove's reader refused mapless's bytes: ${e.message}`);
      continue;
    }
    const want = JSON.parse(fs.readFileSync(path.join(dir, `${name}.json`), "utf8"));
    const d = diff(plain(message), plain(want));
    say(!d, `${name} (${type}, ${bytes.length} bytes): ${d ? `field differs ${d}` : "every field as mapless wrote it"}`);
    say(KNOWN[name] ? KNOWN[name](message) : false, `${name}: the values mapless was told to write`);
  }
} else if (mode === "write") {
  const stamp = { sec: 1700000001, nanosec: 999999999 };
  const grey = Array.from({ length: 6 * 2 }, (_, i) => (i * 37) % 256);
  const messages = {
    image: ["sensor_msgs/msg/Image", { header: { stamp, frame_id: "front_camera" }, height: 2,
      width: 6, encoding: "mono8", is_bigendian: 0, step: 6, data: Uint8Array.from(grey) }],
    compressed_image: ["sensor_msgs/msg/CompressedImage", { header: { stamp, frame_id: "cam" },
      format: "png", data: Uint8Array.from([0x89, 0x50, 0x4e, 0x47, 1, 2, 3]) }],
    odometry: ["nav_msgs/msg/Odometry", {
      header: { stamp, frame_id: "odom" }, child_frame_id: "base_footprint",
      pose: { pose: { position: { x: -3.5, y: 7.125, z: 0.01 },
        orientation: { x: 0, y: 0, z: Math.sin(-1.2 / 2), w: Math.cos(-1.2 / 2) } },
        covariance: Array.from({ length: 36 }, (_, i) => i / 8) },
      twist: { twist: { linear: { x: 0.3, y: 0, z: 0 }, angular: { x: 0, y: 0, z: -0.2 } },
        covariance: Array.from({ length: 36 }, (_, i) => -i) } }],
    bool: ["std_msgs/msg/Bool", { data: true }],
    clock: ["rosgraph_msgs/msg/Clock", { clock: stamp }],
    twist: ["geometry_msgs/msg/Twist", { linear: { x: -0.125, y: 0, z: 0 },
      angular: { x: 0, y: 0, z: 1.75 } }],
    string: ["std_msgs/msg/String", { data: '{"frame":3,"t_s":12.5,"method":"repeat"}' }],
  };
  for (const [name, [type, msg]] of Object.entries(messages)) {
    const bytes = new MessageWriter(definition(type)).writeMessage(msg);
    fs.writeFileSync(path.join(dir, `${name}.in.cdr`), bytes);
    fs.writeFileSync(path.join(dir, `${name}.in.expected.json`), JSON.stringify(plain(msg)));
    say(true, `${name}: ${type} encoded by Foxglove (${bytes.length} bytes)`);
  }
} else if (mode === "check") {
  const expected = names(".in.expected.json");
  for (const name of expected) {
    const want = JSON.parse(fs.readFileSync(path.join(dir, `${name}.in.expected.json`), "utf8"));
    const file = path.join(dir, `${name}.in.decoded.json`);
    if (!fs.existsSync(file)) { say(false, `${name}: mapless did not decode it`); continue; }
    const got = JSON.parse(fs.readFileSync(file, "utf8"));
    const d = diff(plain(got), plain(want));
    say(!d, `${name}: ${d ? `mapless read ${d}` : "mapless reads every field Foxglove wrote"}`);
  }
  say(expected.length === 7, `${expected.length} message types checked (7 expected)`);
} else {
  console.error("usage: node interop.mjs read|write|check DIR");
  process.exit(2);
}
process.exit(failures === 0 ? 0 : 1);
