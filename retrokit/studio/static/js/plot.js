// A small line plot on a canvas: the scenario's reward and cumulative reward over the last frames, with the
// frames where the episode was done shaded. Each series has its own vertical scale (a reward of 1 a frame
// and a total of 3,000 would not both be readable on one), and its range is written beside its name.

const COLORS = { reward: "#5aa9ff", total: "#62d38a", done: "rgba(255,123,114,0.35)" };

function range(values) {
  let lo = Math.min(0, ...values);
  let hi = Math.max(0, ...values);
  if (lo === hi) hi = lo + 1;
  return [lo, hi];
}

/**
 * Draw samples [[frame, reward, total, done], ...] (oldest first) into the canvas.
 * The canvas is sized to its box on the page times the device pixel ratio, so lines stay sharp.
 */
export function drawPlot(canvas, samples) {
  const ratio = window.devicePixelRatio || 1;
  const width = Math.max(1, Math.round(canvas.clientWidth * ratio));
  const height = Math.max(1, Math.round(canvas.clientHeight * ratio));
  if (canvas.width !== width || canvas.height !== height) {
    canvas.width = width;
    canvas.height = height;
  }
  const g = canvas.getContext("2d");
  g.clearRect(0, 0, width, height);
  if (samples.length === 0) return;
  const first = samples[0][0];
  const last = samples[samples.length - 1][0];
  const span = Math.max(1, last - first);
  const x = (frame) => ((frame - first) / span) * (width - 2) + 1;
  const pad = 6 * ratio;

  g.fillStyle = COLORS.done;
  for (const [frame, , , done] of samples) if (done) g.fillRect(x(frame), 0, Math.max(1, width / span), height);

  for (const [index, name] of [[1, "reward"], [2, "total"]]) {
    const [lo, hi] = range(samples.map((s) => s[index]));
    const y = (v) => height - pad - ((v - lo) / (hi - lo)) * (height - 2 * pad);
    g.strokeStyle = "rgba(255,255,255,0.15)";
    g.beginPath();
    g.moveTo(0, y(0));
    g.lineTo(width, y(0));
    g.stroke();
    g.strokeStyle = COLORS[name];
    g.lineWidth = 1.5 * ratio;
    g.beginPath();
    samples.forEach((s, i) => (i ? g.lineTo(x(s[0]), y(s[index])) : g.moveTo(x(s[0]), y(s[index]))));
    g.stroke();
  }
}

/** The range of a series, for the legend: "0 … 12.5". */
export function rangeText(values) {
  if (values.length === 0) return "";
  const [lo, hi] = [Math.min(...values), Math.max(...values)];
  const f = (v) => (Number.isInteger(v) ? String(v) : v.toFixed(2));
  return lo === hi ? f(lo) : `${f(lo)} … ${f(hi)}`;
}
