// The JSON API (docs/studio-api.md). Every request carries the studio's token in the header the server checks
// (X-Retrokit-Token): the page's own URL has it in ?token=, which is where the user's link put it.

/** The token of the URL the studio printed; the server refuses every request without it. */
export const token = new URLSearchParams(location.search).get("token") ?? "";

/** An error the server answered with: its one-line message, its kind (the RetrokitError class), and the whole
 * JSON answer (a scenario's error also carries its line and column). */
export class ApiError extends Error {
  constructor(message, kind, status, data = null) {
    super(message);
    this.kind = kind;
    this.status = status;
    this.data = data;
  }
}

/**
 * Call the API: api("GET", "info"), api("POST", "search/filter", {op: "equal", value: 3}).
 * Returns the parsed JSON answer; throws ApiError with the server's message on a 4xx/5xx.
 */
export async function api(method, path, body) {
  const init = { method, headers: { "X-Retrokit-Token": token } };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch(`/api/${path}`, init);
  } catch (error) {
    throw new ApiError(`The studio's server does not answer (${error.message}); is \`retrokit studio\` still running?`,
      "ConnectionError", 0);
  }
  const type = response.headers.get("Content-Type") ?? "";
  const data = type.includes("json") ? await response.json().catch(() => null) : await response.blob();
  if (!response.ok) {
    const message = data && typeof data.error === "string" ? data.error : `HTTP ${response.status} from /api/${path}`;
    throw new ApiError(message, data?.kind ?? "HTTPError", response.status, data instanceof Blob ? null : data);
  }
  return data;
}

export const get = (path) => api("GET", path);
export const post = (path, body = {}) => api("POST", path, body);
