// The player's buttons from the keyboard, the buttons drawn on the page and the Gamepad API, merged into one
// set and sent to the server only when it changes (the server holds the last set until told otherwise).
//
// The maps come from the server (/api/info "keys" and "gamepad") so the page and docs/studio.md agree on them:
// the arrows are the D-pad and Enter is the system's start button (START; RUN on a PC Engine, RESET on a 2600).

import { send } from "./socket.js";

const held = { keys: new Set(), pointer: new Set(), pad: new Set() };
let last = "";
let keyMap = {};
let padMap = {};
let onChange = () => {};

/** Keys typed into a box (a filter, the scenario editor) are text, not buttons. */
function typing(event) {
  const target = event.target;
  return target instanceof HTMLElement && (target.isContentEditable || ["INPUT", "TEXTAREA", "SELECT"].includes(target.tagName)
    || target.closest(".CodeMirror") !== null);
}

function flush() {
  const buttons = [...new Set([...held.keys, ...held.pointer, ...held.pad])].sort();
  const text = buttons.join("+");
  if (text === last) return;
  last = text;
  send({ type: "buttons", buttons });
  onChange(new Set(buttons));
}

/** The buttons held now, as the server was last told. */
export function current() {
  return last ? last.split("+") : [];
}

/** Press or release a button drawn on the page (mouse or touch). */
export function pointer(button, down) {
  if (down) held.pointer.add(button);
  else held.pointer.delete(button);
  flush();
}

function pollPads() {
  held.pad.clear();
  for (const pad of navigator.getGamepads ? navigator.getGamepads() : []) {
    if (!pad) continue;
    pad.buttons.forEach((b, index) => {
      const button = padMap[String(index)];
      if (button && b.pressed) held.pad.add(button);
    });
    // The left stick works as the D-pad too, with a dead zone so a resting stick presses nothing.
    const [x = 0, y = 0] = pad.axes;
    for (const [button, on] of [["LEFT", x < -0.5], ["RIGHT", x > 0.5], ["UP", y < -0.5], ["DOWN", y > 0.5]]) {
      if (on && Object.values(padMap).includes(button)) held.pad.add(button);
    }
  }
  flush();
}

/**
 * Start listening. info is /api/info; changed(set) is called with the buttons held after each change, so the
 * page can light the drawn buttons up.
 */
export function start(info, changed) {
  keyMap = info.keys ?? {};
  padMap = info.gamepad ?? {};
  onChange = changed;
  window.addEventListener("keydown", (event) => {
    const button = keyMap[event.code];
    if (!button || typing(event) || event.ctrlKey || event.metaKey || event.altKey) return;
    event.preventDefault(); // the arrows would scroll the page, Enter would press a focused button
    held.keys.add(button);
    flush();
  });
  window.addEventListener("keyup", (event) => {
    const button = keyMap[event.code];
    if (!button) return;
    held.keys.delete(button);
    flush();
  });
  // A key released while another window has the focus never sends keyup: let go of everything instead of
  // leaving the player running right forever.
  window.addEventListener("blur", () => {
    held.keys.clear();
    held.pointer.clear();
    flush();
  });
  // Gamepads are polled (the Gamepad API has no button events), only once one has been seen.
  let polling = false;
  window.addEventListener("gamepadconnected", () => {
    if (polling) return;
    polling = true;
    const loop = () => {
      pollPads();
      requestAnimationFrame(loop);
    };
    requestAnimationFrame(loop);
  });
}

/** The keyboard key of each button, for the legend: {"RIGHT": "ArrowRight", ...}. */
export function keysByButton() {
  const out = {};
  for (const [code, button] of Object.entries(keyMap)) out[button] ??= code;
  return out;
}

/** A KeyboardEvent.code as a person reads it: "ArrowRight" -> "→", "KeyZ" -> "Z". */
export function keyLabel(code) {
  const arrows = { ArrowUp: "↑", ArrowDown: "↓", ArrowLeft: "←", ArrowRight: "→" };
  if (arrows[code]) return arrows[code];
  if (/^Key[A-Z]$/.test(code)) return code.slice(3);
  if (/^Digit\d$/.test(code)) return code.slice(5);
  return code.replace(/(Left|Right)$/, " $1").trim();
}
