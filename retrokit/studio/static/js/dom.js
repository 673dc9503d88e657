// Building the page's elements. Everything the server sends (names, messages, values) goes into the DOM as
// text through these helpers, never as HTML: a field or state name is the user's, and a message can quote a
// file's content, so neither may ever be parsed as markup.

/**
 * Make an element: el("button", {class: "small", onclick: fn}, "Save").
 * Attributes starting with "on" become listeners; other attributes are set as attributes; children are nodes
 * or strings (strings become text nodes).
 */
export function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [name, value] of Object.entries(attrs)) {
    if (value === undefined || value === null || value === false) continue;
    if (name.startsWith("on") && typeof value === "function") node.addEventListener(name.slice(2), value);
    else if (name === "dataset") Object.assign(node.dataset, value);
    else node.setAttribute(name, value === true ? "" : String(value));
  }
  append(node, children);
  return node;
}

/** Append children (nodes, strings, numbers, arrays of them; null and false are skipped). */
export function append(node, children) {
  for (const child of children.flat(Infinity)) {
    if (child === null || child === undefined || child === false) continue;
    node.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return node;
}

/** Replace a node's children. */
export function replace(node, ...children) {
  node.replaceChildren();
  return append(node, children);
}

/** The element with this id (the page's fixed skeleton: a missing one is a bug, so say which). */
export function byId(id) {
  const node = document.getElementById(id);
  if (!node) throw new Error(`the page has no element #${id}`);
  return node;
}

// The hex digits of this console's addresses, as the CLI and game.yaml write them (/api/info's ram.digits: 4 on a
// NES, 6 on a Genesis), set once the page knows its game.
let addressDigits = 6;

/** Write addresses of a console whose highest mapped address takes ``digits`` hex digits. */
export function setAddressDigits(digits) {
  addressDigits = digits;
}

/** A console address as the CLI writes it: 0xFF002B on a Genesis, 0x0300 on a NES. */
export function hex(address, digits = addressDigits) {
  return "0x" + Number(address).toString(16).toUpperCase().padStart(digits, "0");
}

/**
 * Read a number typed by the user: decimal, or hex with 0x, optionally negative. Returns null for an empty box
 * and throws a readable Error for anything else, so a typo is reported next to the box instead of sent.
 */
export function parseNumber(text, what = "number") {
  const t = String(text).trim();
  if (t === "") return null;
  const m = /^(-?)(0x[0-9a-f]+|\d+)$/i.exec(t);
  if (!m) throw new Error(`Expected a whole number as the ${what} (e.g. 3, -1 or 0xFF002B), got '${t}'.`);
  const n = Number.parseInt(m[2], m[2].toLowerCase().startsWith("0x") ? 16 : 10);
  return m[1] ? -n : n;
}
