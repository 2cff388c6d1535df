// Decode a rosbag2 MCAP file as Foxglove opens it: its MCAP reader (@mcap/core), its ROS 2
// .msg parser (@foxglove/rosmsg) and its CDR message reader (@foxglove/rosmsg2-serialization).
//
//   node decode_bag.mjs BAG.mcap [TOPIC...]
//
// Prints one JSON object: every channel's topic, schema name and message count, the messages
// that failed to decode (topic and error), and every decoded message of the named topics.
import { open } from "node:fs/promises";
import process from "node:process";

import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { McapIndexedReader } from "@mcap/core";

const [path, ...wanted] = process.argv.slice(2);
const file = await open(path, "r");
const readable = {
  size: async () => BigInt((await file.stat()).size),
  read: async (offset, size) => {
    const buffer = new Uint8Array(Number(size));
    await file.read(buffer, 0, buffer.length, Number(offset));
    return buffer;
  },
};
const reader = await McapIndexedReader.Initialize({ readable });
const readers = new Map();
const topics = {};
const failures = [];
const messages = Object.fromEntries(wanted.map((topic) => [topic, []]));
for (const channel of reader.channelsById.values()) {
  const schema = reader.schemasById.get(channel.schemaId);
  topics[channel.topic] = { schema: schema.name, encoding: schema.encoding, count: 0 };
  try {
    const definition = new TextDecoder().decode(schema.data);
    readers.set(channel.id, new MessageReader(parse(definition, { ros2: true })));
  } catch (error) {
    failures.push({ topic: channel.topic, error: `schema: ${error.message}` });
  }
}
for await (const message of reader.readMessages()) {
  const channel = reader.channelsById.get(message.channelId);
  topics[channel.topic].count += 1;
  const messageReader = readers.get(channel.id);
  if (messageReader === undefined) {
    continue;
  }
  try {
    const decoded = messageReader.readMessage(message.data);
    if (channel.topic in messages) {
      messages[channel.topic].push({ logTime: message.logTime, message: decoded });
    }
  } catch (error) {
    failures.push({ topic: channel.topic, error: error.message });
  }
}
await file.close();
const json = (key, value) => (typeof value === "bigint" ? Number(value) : value);
process.stdout.write(JSON.stringify({ topics, failures, messages }, json));
