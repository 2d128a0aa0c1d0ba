// smoothtrace scene builder: holds the view (the JSON the server's /api/render,
// /api/probe and /api/save read), redraws it progressively (1/8, 1/4, 1/2, full
// resolution; a newer view makes the server cancel older passes, which answer 409),
// and maps mouse and touch to orbit, pan and zoom.
"use strict";

const $ = (id) => document.getElementById(id);
const PASSES = [8, 4, 2, 1];
const KINDS = ["points", "edges", "triangles"];
let info = null;
let view = null;
let token = 0;
let completed = 0;

// ---- small vector helpers -------------------------------------------------------
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const len = (a) => Math.sqrt(dot(a, a));
const norm = (a) => mul(a, 1 / (len(a) || 1));
// Rotates v about unit axis k by angle t (Rodrigues).
function rotate(v, k, t) {
  const c = Math.cos(t), s = Math.sin(t);
  return add(add(mul(v, c), mul(cross(k, v), s)), mul(k, dot(k, v) * (1 - c)));
}
const fmt = (x) => (typeof x === "number" ? Number(x.toPrecision(6)).toString() : String(x));
const fmtv = (v) => (v ? "[" + v.map(fmt).join(", ") + "]" : "-");

// ---- rendering --------------------------------------------------------------------
function body(extra) {
  return JSON.stringify(Object.assign({}, view, extra || {}));
}

function showError(text) {
  $("error").textContent = text || "";
}

// Redraws the view pass by pass; a newer call stops the older loop.
async function refresh() {
  const my = ++token;
  showError("");
  for (const scale of PASSES) {
    let r;
    try {
      r = await fetch("/api/render", { method: "POST", body: body({ scale }) });
    } catch (e) {
      if (my === token) showError("the server does not answer: " + e);
      return;
    }
    if (my !== token || r.status === 409) return;
    if (!r.ok) {
      showError(`${r.status}: ${await r.text()}`);
      return;
    }
    const blob = await r.blob();
    if (my !== token) return;
    const img = $("view");
    const url = URL.createObjectURL(blob);
    img.onload = () => URL.revokeObjectURL(url);
    img.src = url;
    img.dataset.scale = String(scale);
    img.classList.toggle("sharp", scale === 1);
    $("status").textContent = `pass 1/${scale}: ${r.headers.get("X-Render-Stats") || ""}`;
  }
  completed += 1;
  $("view").dataset.completed = String(completed);
}

function setSize() {
  const img = $("view");
  img.style.width = view.width + "px";
  img.style.height = view.height + "px";
}

// ---- camera -----------------------------------------------------------------------
function basis() {
  const c = view.camera;
  const f = norm(sub(c.target, c.origin));
  const r = norm(cross(f, c.up));
  const u = cross(r, f);
  return { f, r, u };
}

function orbit(dx, dy) {
  const c = view.camera;
  const up = norm(c.up);
  let off = sub(c.origin, c.target);
  off = rotate(off, up, -dx * 0.008);
  const { r } = basis();
  const turned = rotate(off, r, -dy * 0.008);
  // Stop short of the poles (the up vector must not become the view direction).
  if (Math.abs(dot(norm(turned), up)) < 0.995) off = turned;
  c.origin = add(c.target, off);
}

function pan(dx, dy) {
  const c = view.camera;
  const dist = len(sub(c.origin, c.target));
  const perPixel = (2 * dist * Math.tan((c.fov * Math.PI) / 360)) / view.height;
  const { r, u } = basis();
  const move = add(mul(r, -dx * perPixel), mul(u, dy * perPixel));
  c.origin = add(c.origin, move);
  c.target = add(c.target, move);
}

function zoom(factor) {
  const c = view.camera;
  c.origin = add(c.target, mul(sub(c.origin, c.target), factor));
}

function bindPointer() {
  const frame = $("frame");
  const pointers = new Map();
  let moved = 0;
  let pinch = 0;
  frame.addEventListener("contextmenu", (e) => e.preventDefault());
  frame.addEventListener("pointerdown", (e) => {
    frame.setPointerCapture(e.pointerId);
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY, button: e.button, shift: e.shiftKey });
    moved = 0;
    pinch = 0;
    frame.classList.add("dragging");
  });
  frame.addEventListener("pointermove", (e) => {
    const p = pointers.get(e.pointerId);
    if (!p) return;
    const dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX;
    p.y = e.clientY;
    moved += Math.abs(dx) + Math.abs(dy);
    if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const d = Math.hypot(a.x - b.x, a.y - b.y);
      if (pinch > 0) zoom(pinch / d);
      pinch = d;
    } else if (p.button === 2 || p.shift) {
      pan(dx, dy);
    } else {
      orbit(dx, dy);
    }
    if (dx || dy) refresh();
  });
  const end = (e) => {
    const p = pointers.get(e.pointerId);
    pointers.delete(e.pointerId);
    if (pointers.size === 0) frame.classList.remove("dragging");
    if (p && moved < 3 && e.type === "pointerup" && p.button === 0) {
      const rect = $("view").getBoundingClientRect();
      probe(e.clientX - rect.left, e.clientY - rect.top);
    }
  };
  frame.addEventListener("pointerup", end);
  frame.addEventListener("pointercancel", end);
  frame.addEventListener(
    "wheel",
    (e) => {
      e.preventDefault();
      zoom(Math.exp(e.deltaY * 0.001));
      refresh();
    },
    { passive: false },
  );
}

// ---- probe ------------------------------------------------------------------------
async function probe(x, y) {
  const r = await fetch("/api/probe", { method: "POST", body: body({ x, y }) });
  const out = $("probe");
  if (!r.ok) {
    out.textContent = `${r.status}: ${await r.text()}`;
    return;
  }
  const p = await r.json();
  out.dataset.json = JSON.stringify(p);
  const lines = [`pixel (${fmt(x)}, ${fmt(y)})`];
  if (!p.hit) {
    lines.push("no hit");
  } else {
    lines.push(
      `hit point ${fmtv(p.point)} (t = ${fmt(p.t)}, object ${p.object})`,
      `s = ${fmt(p.s)}`,
      `gradient ${fmtv(p.gradient)}`,
      `exact distance ${fmt(p.distance)}`,
      `nearest: ${p.nearest_kind} #${p.nearest_index} at ${fmtv(p.nearest_point)}`,
      `alpha ${fmt(p.alpha)}, max_alpha ${fmt(p.max_alpha)}, beta ${fmt(p.beta)}`,
    );
  }
  lines.push(`ray: ${p.evals} evaluations + ${p.coarse_evals} bound steps, ${p.leaves} leaves`);
  out.textContent = lines.join("\n");
}

// ---- controls ---------------------------------------------------------------------
// An alpha slider (log scale) for object k's `key` ("alpha" or "max_alpha"), kept in the
// object's own form (absolute, or `_rel`: times the diagonal).
function alphaControl(k, key, parent) {
  const o = view.objects[k];
  const diag = info.diagonals[k] || 1;
  const rel = () => o[key + "_rel"] !== undefined && o[key + "_rel"] !== null;
  const absolute = () => (rel() ? o[key + "_rel"] / diag : o[key]);
  const label = document.createElement("label");
  const slider = document.createElement("input");
  slider.type = "range";
  slider.id = `obj${k}-${key}`;
  slider.step = "0.01";
  const out = document.createElement("span");
  out.className = "value";
  label.append(key + " ", slider, document.createElement("br"), out);
  parent.append(label);
  const show = () => {
    const a = absolute();
    out.textContent = a === undefined || a === null ? "same as alpha" : `${fmt(a)} (x diagonal = ${fmt(a * diag)})`;
  };
  const start = absolute() ?? o.alpha ?? o.alpha_rel / diag;
  const centre = Math.log10(start);
  slider.min = String(centre - 3);
  slider.max = String(centre + 3);
  slider.value = String(centre);
  slider.addEventListener("input", () => {
    const a = Math.pow(10, Number(slider.value));
    if (rel()) o[key + "_rel"] = a * diag;
    else o[key] = a;
    show();
    refresh();
  });
  show();
  return { slider, show };
}

function objectControls() {
  const box = $("objects");
  view.objects.forEach((o, k) => {
    const fs = document.createElement("fieldset");
    const legend = document.createElement("legend");
    legend.textContent = `object ${k}: ${info.objects[k]}`;
    fs.append(legend);
    const kinds = document.createElement("div");
    for (const kind of KINDS) {
      const l = document.createElement("label");
      l.style.display = "inline-block";
      const c = document.createElement("input");
      c.type = "checkbox";
      c.id = `obj${k}-${kind}`;
      c.checked = o.primitives.includes(kind);
      c.addEventListener("change", () => {
        const chosen = KINDS.filter((n) => $(`obj${k}-${n}`).checked);
        if (chosen.length === 0) {
          c.checked = true;
          return;
        }
        o.primitives = chosen;
        refresh();
      });
      l.append(c, " " + kind + " ");
      kinds.append(l);
    }
    fs.append(kinds);
    alphaControl(k, "alpha", fs);
    const same = document.createElement("label");
    const sameBox = document.createElement("input");
    sameBox.type = "checkbox";
    sameBox.id = `obj${k}-max-same`;
    const hasMax = () => o.max_alpha != null || o.max_alpha_rel != null;
    sameBox.checked = !hasMax();
    same.append(sameBox, " max_alpha same as alpha");
    fs.append(same);
    const maxBox = document.createElement("div");
    fs.append(maxBox);
    let maxControl = null;
    const showMax = () => {
      maxBox.replaceChildren();
      if (sameBox.checked) return;
      if (!hasMax()) {
        if (o.alpha_rel != null) o.max_alpha_rel = o.alpha_rel;
        else o.max_alpha = o.alpha;
      }
      maxControl = alphaControl(k, "max_alpha", maxBox);
    };
    sameBox.addEventListener("change", () => {
      if (sameBox.checked) {
        delete o.max_alpha;
        delete o.max_alpha_rel;
      }
      showMax();
      refresh();
    });
    showMax();
    const ml = document.createElement("label");
    const sel = document.createElement("select");
    sel.id = `obj${k}-matcap`;
    const names = info.matcaps.includes(o.matcap) ? info.matcaps : [o.matcap, ...info.matcaps];
    for (const n of names) sel.append(new Option(n, n, false, n === o.matcap));
    sel.append(new Option("file in the scene's folder...", "__file"));
    const file = document.createElement("input");
    file.type = "text";
    file.placeholder = "matcaps/x.png";
    file.hidden = true;
    sel.addEventListener("change", () => {
      file.hidden = sel.value !== "__file";
      if (sel.value !== "__file") {
        o.matcap = sel.value;
        refresh();
      }
    });
    file.addEventListener("change", () => {
      o.matcap = file.value;
      refresh();
    });
    ml.append("matcap ", sel, " ", file);
    fs.append(ml);
    box.append(fs);
    void maxControl;
  });
}

function renderControls() {
  const beta = $("beta");
  beta.value = String(view.beta);
  $("beta-out").textContent = fmt(view.beta);
  beta.addEventListener("input", () => {
    view.beta = Number(beta.value);
    $("beta-out").textContent = fmt(view.beta);
    refresh();
  });
  const eps = $("epsilon");
  eps.value = String(view.epsilon_rel ?? "");
  if (view.epsilon_rel == null) eps.placeholder = `absolute ${fmt(view.epsilon)}`;
  eps.addEventListener("change", () => {
    delete view.epsilon;
    view.epsilon_rel = Number(eps.value);
    refresh();
  });
  $("samples").addEventListener("change", () => {
    view.samples = Number($("samples").value);
    refresh();
  });
  $("aov").addEventListener("change", () => {
    view.aov = $("aov").value;
    refresh();
  });
  for (const key of ["width", "height"]) {
    const input = $(key);
    input.max = String(info.max_size);
    input.value = String(view[key]);
    input.addEventListener("change", () => {
      view[key] = Math.round(Number(input.value));
      setSize();
      refresh();
    });
  }
}

function download(blob, name) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

function outputControls() {
  $("save").addEventListener("click", async () => {
    const r = await fetch("/api/save", { method: "POST", body: body() });
    if (!r.ok) return showError(`${r.status}: ${await r.text()}`);
    download(await r.blob(), "scene.toml");
  });
  $("png").addEventListener("click", async () => {
    $("status").textContent = "rendering the full-resolution PNG...";
    const r = await fetch("/api/render", { method: "POST", body: body({ scale: 1, keep: true }) });
    if (!r.ok) return showError(`${r.status}: ${await r.text()}`);
    download(await r.blob(), "render.png");
    $("status").textContent = `full PNG: ${r.headers.get("X-Render-Stats") || ""}`;
  });
  if (info.save_as) {
    $("server-save").hidden = false;
    $("save-name").value = info.save_as;
    $("save-server").addEventListener("click", async () => {
      const r = await fetch("/api/save", { method: "POST", body: body({ save_as: $("save-name").value }) });
      if (!r.ok) return showError(`${r.status}: ${await r.text()}`);
      $("status").textContent = `saved to ${r.headers.get("X-Saved-To")}`;
    });
  }
}

async function main() {
  const r = await fetch("/api/scene");
  info = await r.json();
  view = info.view;
  $("scene-name").textContent = info.scene;
  setSize();
  objectControls();
  renderControls();
  outputControls();
  bindPointer();
  refresh();
}

main();
