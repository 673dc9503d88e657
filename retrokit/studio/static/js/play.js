// Play: the live screen, the status line, pause / frame advance / speed / reset, and the buttons with their keys.
//
// Screens come from the socket as raw pixels; only the newest is drawn, once per animation frame, so a fast
// game (8x) never queues drawing work behind the display.

import { byId, el, replace } from "./dom.js";
import * as input from "./input.js";
import { on, onScreen, send } from "./socket.js";

const SPEEDS = [0.25, 0.5, 1, 2, 4, 8];
// Milliseconds between updates of the frame number shown under the screen while the game runs. Its text changing
// on every frame laid out the page 60 times a second (a fifth of what Chromium spent on a playing page), for a
// number no one reads at that rate; paused, it is the exact frame of the screen (showFrame).
const FRAME_TEXT_PERIOD = 100;

let pending = null; // the newest screen not drawn yet
let image = null;
let status = {};
let frameTextAt = -Infinity; // when the frame number shown was last written (performance.now())

/** Write the frame number of the canvas under the screen: at once when paused (or asked), else at most once a period. */
function showFrame(now = false) {
  const frame = byId("screen").dataset.frame;
  if (frame === undefined) return;
  const at = performance.now();
  if (!now && !status.paused && at - frameTextAt < FRAME_TEXT_PERIOD) return;
  frameTextAt = at;
  const shown = byId("frame");
  if (shown.textContent !== frame) shown.textContent = frame;
}

function draw(canvas) {
  const screen = pending;
  pending = null;
  if (!screen) return;
  const { width, height, depth, pixels, frame } = screen;
  if (canvas.width !== width || canvas.height !== height) {
    canvas.width = width;
    canvas.height = height;
    image = null;
  }
  image ??= new ImageData(width, height);
  const out = image.data;
  if (depth === 4) out.set(pixels.subarray(0, width * height * 4));
  else {
    for (let i = 0, j = 0; j < width * height * 4; i += depth, j += 4) {
      out[j] = pixels[i];
      out[j + 1] = pixels[i + 1];
      out[j + 2] = pixels[i + 2];
      out[j + 3] = 255;
    }
  }
  canvas.getContext("2d").putImageData(image, 0, 0);
  // The frame number shown is the one of the pixels on the canvas (tests and the benchmark read it here).
  canvas.dataset.frame = String(frame);
  showFrame();
}

function showStatus(message) {
  status = { ...status, ...message };
  byId("fps").textContent = typeof status.fps === "number" ? status.fps.toFixed(1) : "";
  byId("speed-shown").textContent = `${status.speed ?? 1}×`;
  const pause = byId("pause");
  pause.textContent = status.paused ? "Resume" : "Pause";
  pause.setAttribute("aria-pressed", status.paused ? "true" : "false");
  byId("play").classList.toggle("paused", Boolean(status.paused));
  byId("run-state").textContent = status.paused ? "paused" : status.replaying ? "replaying" : "running";
  if (typeof status.speed === "number") byId("speed").value = String(status.speed);
  if (status.state) byId("current-state").textContent = status.state;
  if (status.paused) showFrame(true); // the screen drawn before this status said so
}

/** The buttons of the system, each with its key, pressable with the mouse too. */
function legend(info) {
  const keys = input.keysByButton();
  const pad = byId("buttons");
  replace(pad, ...info.buttons.map((button) => {
    const key = keys[button];
    const node = el("button", { type: "button", class: "pad-button", "data-button": button,
      title: key ? `${button}: key ${input.keyLabel(key)}` : `${button}: no key; press it here` },
    el("span", { class: "name" }, button), el("kbd", {}, key ? input.keyLabel(key) : "–"));
    node.addEventListener("pointerdown", (event) => {
      node.setPointerCapture(event.pointerId);
      input.pointer(button, true);
    });
    for (const end of ["pointerup", "pointercancel"]) node.addEventListener(end, () => input.pointer(button, false));
    return node;
  }));
}

function lightUp(held) {
  for (const node of byId("buttons").querySelectorAll(".pad-button")) {
    node.classList.toggle("held", held.has(node.dataset.button));
  }
}

/** Fill the reset menu with the game's states (called again when a state is saved). */
export function setStates(states, preferred) {
  const select = byId("reset-state");
  const keep = preferred ?? select.value;
  replace(select, el("option", { value: "" }, "(the state it began from)"),
    states.map((name) => el("option", { value: name }, name)));
  if (states.includes(keep)) select.value = keep;
}

/** Build the panel from /api/info. */
export function init(info) {
  const canvas = byId("screen");
  canvas.width = info.width;
  canvas.height = info.height;
  onScreen((screen) => {
    if (!pending) requestAnimationFrame(() => draw(canvas));
    pending = screen;
  });
  on("status", showStatus);
  on("connection", ({ connected }) => {
    byId("connection").textContent = connected ? "connected" : "disconnected: reconnecting…";
    byId("connection").className = connected ? "ok" : "error";
  });

  const speed = byId("speed");
  replace(speed, SPEEDS.map((s) => el("option", { value: String(s) }, `${s}×`)));
  speed.value = String(info.status?.speed ?? 1);
  speed.addEventListener("change", () => send({ type: "speed", value: Number(speed.value) }));
  byId("pause").addEventListener("click", () => send({ type: status.paused ? "resume" : "pause" }));
  byId("step").addEventListener("click", () => {
    const frames = Number.parseInt(byId("step-frames").value, 10);
    send({ type: "step", frames: Number.isFinite(frames) && frames > 0 ? frames : 1 });
  });
  byId("reset").addEventListener("click", () => send({ type: "reset", state: byId("reset-state").value || null }));
  setStates(info.states ?? [], info.status?.state);

  input.start(info, lightUp);
  legend(info);
  showStatus(info.status ?? {});
}

/** The canvas and the console pixel under a mouse event (for click to find). */
export function pixelAt(event) {
  const canvas = byId("screen");
  const box = canvas.getBoundingClientRect();
  const x = Math.floor(((event.clientX - box.left) / box.width) * canvas.width);
  const y = Math.floor(((event.clientY - box.top) / box.height) * canvas.height);
  return { x: Math.min(Math.max(x, 0), canvas.width - 1), y: Math.min(Math.max(y, 0), canvas.height - 1) };
}
