// Foxglove's own WebSocket client (@foxglove/ws-protocol, the one the Foxglove app builds on),
// driven by a test through JSON lines: commands on stdin, what the server says on stdout.
//
//   node client.mjs ws://127.0.0.1:PORT [--count]
//
// With --count, messages are counted, not said: {"op": "counts"} answers {"event": "counts",
// "counts": {topic: [messages, bytes, last log time]}} (a benchmark's client, which reads at
// full speed without a test reading its lines).
//
// Commands: {"op": "subscribe", "topics": [...]} subscribes to each topic once it is advertised
// (and again when the server refuses a subscription to a channel it has only just advertised:
// foxglove-sdk 0.30.3 can, with "Unknown channel ID"); {"op": "unsubscribe", "topics": [...]};
// {"op": "advertise", "topic", "encoding",
// "schemaName"} answers {"event": "advertised", "topic", "channel"}; {"op": "publish",
// "channel", "text"} sends the text's bytes; {"op": "subscribeAll", "schemaPrefix", "topics"} subscribes to
// every channel, advertised already or later (with "schemaPrefix", to those whose schema name
// starts with it, and the "topics"); {"op": "getParameters", "names", "id"};
// {"op": "setParameters", "parameters", "id"}; {"op": "pause"} and {"op": "resume"} stop and
// start reading the socket (a client that reads nothing); {"op": "close"}.
//
// Events: serverInfo, advertise (the channels), message (topic, logTime as a decimal string,
// data in base64), status, parameterValues, close, error.

import wsProtocol from "@foxglove/ws-protocol";
import readline from "node:readline";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol; // a CommonJS package: its exports come as the default

const UNKNOWN_CHANNEL = "Unknown channel ID: ";
const SDK_SUBPROTOCOL = "foxglove.sdk.v1"; // the one foxglove-sdk 0.30's server speaks

// As the Foxglove app does: both subprotocols offered, the server picks.
const counting = process.argv.includes("--count");
const counts = {}; // topic -> [messages, bytes, last log time]
const ws = new WebSocket(process.argv[2], [SDK_SUBPROTOCOL, FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const channels = new Map(); // topic -> channel
const wanted = new Set(); // topics to subscribe to
let everything = null; // which channels to subscribe to, those advertised later too
const subscribed = new Map(); // subscription id -> topic
const subscriptionOf = new Map(); // topic -> subscription id

function say(event) {
  process.stdout.write(JSON.stringify(event) + "\n");
}

function subscribeWanted() {
  const chosen = everything
    ? [...channels.values()].filter(everything).map((channel) => channel.topic)
    : wanted;
  for (const topic of chosen) {
    const channel = channels.get(topic);
    if (channel !== undefined && !subscriptionOf.has(topic)) {
      const id = client.subscribe(channel.id);
      subscribed.set(id, topic);
      subscriptionOf.set(topic, id);
    }
  }
}

client.on("serverInfo", (info) => say({ event: "serverInfo", ...info }));
client.on("advertise", (advertised) => {
  for (const channel of advertised) channels.set(channel.topic, channel);
  say({ event: "advertise", channels: advertised });
  subscribeWanted();
});
client.on("status", (status) => {
  say({ event: "status", ...status });
  if (status.message.startsWith(UNKNOWN_CHANNEL)) {
    const unknown = Number(status.message.slice(UNKNOWN_CHANNEL.length));
    for (const [topic, channel] of channels) {
      if (channel.id === unknown && subscriptionOf.has(topic)) {
        subscribed.delete(subscriptionOf.get(topic));
        subscriptionOf.delete(topic);
      }
    }
    subscribeWanted();
  }
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  if (counting) {
    const topic = subscribed.get(subscriptionId);
    const count = (counts[topic] ??= [0, 0, "0"]);
    count[0] += 1;
    count[1] += data.byteLength;
    count[2] = timestamp.toString();
    return;
  }
  const bytes = Buffer.from(data.buffer, data.byteOffset, data.byteLength);
  say({
    event: "message",
    topic: subscribed.get(subscriptionId),
    logTime: timestamp.toString(),
    data: bytes.toString("base64"),
  });
});
client.on("parameterValues", (values) => say({ event: "parameterValues", ...values }));
client.on("error", (error) => say({ event: "error", message: String(error?.message ?? error) }));
client.on("close", (event) => {
  // Exit once the last line is written: an exit at once can cut it.
  process.stdout.write(JSON.stringify({ event: "close", code: event?.code ?? null }) + "\n", () =>
    process.exit(0),
  );
});

const commands = {
  subscribe: ({ topics }) => {
    for (const topic of topics) wanted.add(topic);
    subscribeWanted();
  },
  unsubscribe: ({ topics }) => {
    for (const topic of topics) {
      wanted.delete(topic);
      if (subscriptionOf.has(topic)) {
        client.unsubscribe(subscriptionOf.get(topic));
        subscribed.delete(subscriptionOf.get(topic));
        subscriptionOf.delete(topic);
      }
    }
  },
  advertise: ({ topic, encoding, schemaName }) => {
    const channel = client.advertise({ topic, encoding, schemaName });
    say({ event: "advertised", topic, channel });
  },
  publish: ({ channel, text }) => client.sendMessage(channel, new TextEncoder().encode(text)),
  getParameters: ({ names, id }) => client.getParameters(names ?? [], id),
  setParameters: ({ parameters, id }) => client.setParameters(parameters, id),
  subscribeAll: ({ schemaPrefix, topics }) => {
    everything = (channel) =>
      schemaPrefix === undefined ||
      channel.schemaName.startsWith(schemaPrefix) ||
      (topics ?? []).includes(channel.topic);
    subscribeWanted();
  },
  counts: () => say({ event: "counts", counts }),
  pause: () => ws.pause(),
  resume: () => ws.resume(),
  close: () => client.close(),
};

client.on("open", () => {
  say({ event: "open", protocol: ws.protocol });
  readline.createInterface({ input: process.stdin }).on("line", (line) => {
    const command = JSON.parse(line);
    commands[command.op](command);
  });
});
