// The /ws socket: screens arrive as binary messages, everything else as JSON text with a "type". Panels
// subscribe to the types they show; commands go back as JSON. The socket reconnects by itself, because the
// server pauses the emulator when its last page goes and resumes serving when one comes back.

import { token } from "./api.js";

/** Header of a screen message (retrokit/studio/app.py SCREEN_HEADER): "RKS1", u16 width, u16 height,
 * u32 frame, u8 bytes per pixel, 3 zero bytes, all little-endian; then the pixel rows. */
const HEADER = 16;
const MAGIC = "RKS1";

const listeners = new Map(); // type -> Set of callbacks
let screenListener = null;
let ws = null;
let queue = []; // commands sent while (re)connecting
let retry = 250;

/** Call fn(message) for every JSON message of this type ("*" for all). Returns an unsubscribe function. */
export function on(type, fn) {
  if (!listeners.has(type)) listeners.set(type, new Set());
  listeners.get(type).add(fn);
  return () => listeners.get(type).delete(fn);
}

/** The one consumer of screens: fn({width, height, frame, depth, pixels: Uint8Array}). */
export function onScreen(fn) {
  screenListener = fn;
}

/** Send a command ({type: "buttons", buttons: [...]}, {type: "pause"}, ...). */
export function send(command) {
  const text = JSON.stringify(command);
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(text);
  else if (command.type !== "buttons") queue.push(text); // stale buttons are not worth replaying
}

function emit(type, message) {
  for (const key of [type, "*"]) for (const fn of listeners.get(key) ?? []) fn(message);
}

/** Decode a binary screen message; null when it is not one (a newer server's message the page doesn't know). */
export function decodeScreen(buffer) {
  if (buffer.byteLength < HEADER) return null;
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== MAGIC) return null;
  const width = view.getUint16(4, true);
  const height = view.getUint16(6, true);
  const frame = view.getUint32(8, true);
  const depth = view.getUint8(12);
  const pixels = new Uint8Array(buffer, HEADER);
  if (pixels.length < width * height * depth) return null;
  return { width, height, frame, depth, pixels };
}

/** Open the socket (again). */
export function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  // A browser cannot set headers on a WebSocket, so the token goes in the query, as the server allows.
  // ack=1: this page acknowledges each message, so the server holds back from the first one (push.py).
  ws = new WebSocket(`${scheme}://${location.host}/ws?token=${encodeURIComponent(token)}&ack=1`);
  ws.binaryType = "arraybuffer";
  ws.addEventListener("open", () => {
    retry = 250;
    emit("connection", { type: "connection", connected: true });
    for (const text of queue) ws.send(text);
    queue = [];
  });
  let received = 0; // messages handled on this socket: the server sends only a few ahead of it (push.py)
  const socket = ws;
  ws.addEventListener("message", (event) => {
    try {
      handle(event);
    } finally {
      received += 1;
      if (socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify({ type: "ack", received }));
    }
  });
  ws.addEventListener("close", (event) => {
    emit("connection", { type: "connection", connected: false, reason: event.reason });
    if (event.code === 1008) return; // refused (wrong token or origin): retrying would be refused again
    setTimeout(connect, retry);
    retry = Math.min(retry * 2, 5000);
  });
}

/** Hand one message to its listeners: a screen to the screen's, JSON to its type's. */
function handle(event) {
  if (typeof event.data === "string") {
    let message;
    try {
      message = JSON.parse(event.data);
    } catch {
      return; // not ours to show
    }
    if (message && typeof message.type === "string") emit(message.type, message);
  } else if (screenListener) {
    const screen = decodeScreen(event.data);
    if (screen) screenListener(screen);
  }
}
