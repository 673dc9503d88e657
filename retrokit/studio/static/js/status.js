// One line at the bottom of the page for what just happened: the result of an action, or the server's one-line
// error. Errors stay until the next message so a user can read them; both are plain text.

import { byId } from "./dom.js";

let timer = null;

/** Show a message; kind is "ok" or "error". */
export function say(message, kind = "ok") {
  const line = byId("message");
  line.textContent = message;
  line.className = kind;
  clearTimeout(timer);
  if (kind === "ok") timer = setTimeout(() => { if (line.textContent === message) line.textContent = ""; }, 6000);
}

/** Run work the user did not click for (a compile while typing): report its error, but leave the line alone
 * otherwise, so it does not wipe the outcome of the user's last action. */
export async function background(action) {
  try {
    return await action();
  } catch (error) {
    say(error.message, "error");
    return undefined;
  }
}

/** Run an async action from a button, reporting its error (an ApiError carries the server's line). The line is
 * cleared first, so what it shows afterwards is this action's outcome, not an older one's. */
export async function attempt(action, done) {
  const line = byId("message");
  line.textContent = "";
  line.className = "";
  try {
    const result = await action();
    if (done) say(typeof done === "function" ? done(result) : done);
    return result;
  } catch (error) {
    say(error.message, "error");
    return undefined;
  }
}

/** On the form's submit, instead of the page's navigation, attempt the action (see attempt). */
export function attemptOnSubmit(form, action, done) {
  form.addEventListener("submit", (event) => {
    event.preventDefault();
    attempt(action, done);
  });
}
