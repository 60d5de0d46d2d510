// The cell's dashboard page (deploy/cellctl/dashboard.hpp): follows the cell by server-sent
// events and draws it. Every text that comes from the cell is set as text, never as markup.
"use strict";
(function () {
  // What the page saw, for whoever checks it: each resource's states in turn ("idle", "gone"...).
  const page = (window.dashboard = { states: 0, latencies: [], built: [], received: [], bars: [], state: null, seen: {},
                                     movingFrames: 0, parts: {}, drawMs: { scene: [], gantt: [], tables: [] } });
  let receivedAt = 0; // wall s when the last state came
  let lastHeard = 0;

  function el(tag, text, cls) {
    const e = document.createElement(tag);
    if (text !== undefined && text !== null) e.textContent = String(text);
    if (cls) e.className = cls;
    return e;
  }
  function fill(tbody, rows) {
    tbody.replaceChildren(...rows.map((cells) => {
      const tr = el("tr");
      for (const c of cells) tr.append(c instanceof Node ? wrap(c) : el("td", c));
      return tr;
    }));
  }
  function wrap(node) {
    const td = el("td");
    td.append(node);
    return td;
  }
  function simNow() {
    const s = page.state;
    if (!s) return 0;
    return s.sim_time + (Date.now() / 1000 - receivedAt) * (s.real_time_factor || 1);
  }
  function hue(text) {
    let h = 0;
    for (const c of String(text)) h = (h * 31 + c.charCodeAt(0)) % 360;
    return h;
  }

  function renderResources(resources) {
    fill(document.querySelector("#resources tbody"), resources.map((r) => {
      const word = !r.alive ? "gone" : r.out_of_service ? "out of service" : r.busy ? "busy" : "idle";
      const seen = (page.seen[r.id] = page.seen[r.id] || []);
      if (seen[seen.length - 1] !== word) seen.push(word);
      const ago = r.restarted_at ? Date.now() / 1000 - r.restarted_at : Infinity;
      const state = el("span", word + (r.alive && ago < 60 ? ", restarted " + Math.round(ago) + " s ago" : ""),
                       r.alive && ago < 60 ? "back" : word.replaceAll(" ", "-"));
      if (r.out_of_service) state.title = r.out_of_service;
      const doing = r.current ? r.current.operation + (r.current.part ? " " + r.current.part : "") + " (" + r.current.order + ")" : "";
      const types = Object.entries(r.stock || {});
      const stock = el("span", types.length ? types.reduce((sum, [, n]) => sum + n, 0) + " parts of " + types.length + " types" : "");
      stock.title = types.map(([t, n]) => t + " " + n).join(", ");
      const refused = r.refused ? r.refused + (r.last_refusal ? ": " + r.last_refusal : "") : "";
      return [r.id, r.kind || "", state, doing, r.reserved_by || "", (r.waiting || []).join(", "), r.queued ?? "", refused,
              r.restarts || 0, stock, r.kind === "simulation" ? "" : serviceButton(r.id, !!r.out_of_service)];
    }));
  }
  // Out of service (asking why) and back: a button per resource and way, kept across redraws.
  const serviceButtons = new Map();
  function serviceButton(resource, out) {
    const key = resource + (out ? "/back" : "/out");
    if (serviceButtons.has(key)) return serviceButtons.get(key);
    const button = el("button", out ? "back into service" : "out of service", "service");
    button.addEventListener("click", async () => {
      const why = out ? "" : window.prompt("Take " + resource + " out of service: why? It takes no new work; what it took on, it finishes.");
      if (!out && !why) return;
      await act("/resources/" + encodeURIComponent(resource) + (out ? "/in-service" : "/out-of-service"), why);
    });
    serviceButtons.set(key, button);
    return button;
  }
  function renderOrders(orders) {
    fill(document.querySelector("#orders tbody"), orders.map((o) => {
      const bar = el("progress");
      bar.max = 1;
      bar.value = o.state === "DONE" ? 1 : o.progress || 0;
      const results = el("span");
      if (o.state === "DONE" || o.state === "FAILED") {
        for (const file of ["report.html", "plan.json", "animation.gltf"]) {
          const a = el("a", file.split(".")[0]);
          a.href = "/orders/" + encodeURIComponent(o.order) + "/" + file;
          a.target = "_blank";
          a.rel = "noopener";
          results.append(a, " ");
        }
      }
      if (o.state !== "DONE" && o.state !== "FAILED") results.append(cancelButton(o.order));
      return [o.order + (o.quote ? " (quote)" : ""), el("span", o.state, "state-" + o.state), bar, o.place ?? "",
              o.message || "", o.reason || "", results];
    }));
  }
  // One button per order, kept across redraws: a click between two states still lands.
  const cancelButtons = new Map();
  function cancelButton(order) {
    if (cancelButtons.has(order)) return cancelButtons.get(order);
    const button = el("button", "cancel", "cancel");
    button.addEventListener("click", async () => {
      if (!window.confirm("Cancel order " + order + "? Its twin fails it and the cell cleans up.")) return;
      button.disabled = true;
      await act("/orders/" + encodeURIComponent(order) + "/cancel");
    });
    cancelButtons.set(order, button);
    return button;
  }
  function renderInventory(inventory) {
    fill(document.querySelector("#inventory tbody"), Object.entries(inventory).map(([type, c]) => [
      type, c.initial, c.in_buffers, c.in_transit, c.on_stations, c.assembled, c.inspection,
      el("span", c.conserved ? "yes" : "NO", c.conserved ? "idle" : "gone")]));
  }
  function renderAlarms(alarms) {
    document.getElementById("alarms").replaceChildren(...alarms.map((a) => el("li",
      new Date(a.time * 1000).toLocaleTimeString() + "  " + a.source + " " + a.event + (a.order ? " [" + a.order + "]" : "") +
      (a.detail ? ": " + a.detail : ""))));
  }
  function renderAttention(items) {
    const list = document.getElementById("attention");
    if (!items.length) list.replaceChildren(el("li", "nothing", "calm"));
    else list.replaceChildren(...items.map((a) => el("li", a.what, a.severity)));
  }

  // The Gantt chart: a row per resource, the last hour of sim time, bars coloured by order.
  function renderGantt() {
    const s = page.state;
    const canvas = document.getElementById("gantt");
    if (!s) return;
    const rows = s.resources.map((r) => r.id);
    const rowHeight = 18, left = 120, width = Math.max(600, canvas.parentElement.clientWidth - 4);
    canvas.width = width;
    canvas.height = rows.length * rowHeight + 20;
    const g = canvas.getContext("2d");
    g.clearRect(0, 0, canvas.width, canvas.height);
    // The last hour, or less while the cell has worked less: its work fills the chart.
    const now = simNow();
    const first = page.bars.length ? page.bars[0].start : now;
    const span = Math.min(3600, Math.max(120, (now - first) * 1.05));
    const from = now - span;
    const x = (t) => left + ((t - from) / span) * (width - left);
    g.font = "11px sans-serif";
    rows.forEach((id, i) => {
      g.fillStyle = "#1d2430";
      g.fillText(id, 4, i * rowHeight + 13);
      g.fillStyle = "#e3e6ea";
      g.fillRect(left, i * rowHeight + rowHeight - 1, width - left, 1);
    });
    const draw = (resource, order, start, end, failed) => {
      const i = rows.indexOf(resource);
      if (i < 0 || end < from) return;
      g.fillStyle = failed ? "#b00020" : "hsl(" + hue(order) + ",60%,55%)";
      g.fillRect(x(Math.max(start, from)), i * rowHeight + 3, Math.max(1, x(end) - x(Math.max(start, from))), rowHeight - 6);
    };
    for (const b of page.bars) draw(b.resource, b.order, b.start, b.end, b.state !== "succeeded");
    for (const r of s.resources) if (r.current) draw(r.id, r.current.order, r.current.since, now, false);
    g.fillStyle = "#555";
    const step = span > 1200 ? 600 : span > 300 ? 60 : 30;
    for (let t = now; t >= from; t -= step) {
      g.fillText(Math.round((t - now) / 60 * 10) / 10 + " min", x(t) - 14, canvas.height - 4);
    }
  }

  // The cell in 3D: tables, buffers and robots where their capabilities place them.
  const scene = { ready: false };
  function startScene() {
    const box = document.getElementById("scene");
    if (!window.THREE) return;
    try {
      scene.renderer = new THREE.WebGLRenderer({ antialias: true });
    } catch (e) {
      box.textContent = "no 3D view here: " + e.message;
      return;
    }
    scene.renderer.setSize(box.clientWidth, box.clientHeight);
    box.append(scene.renderer.domElement);
    scene.three = new THREE.Scene();
    scene.three.background = new THREE.Color(0xeef1f5);
    scene.three.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 1.0));
    const floor = new THREE.GridHelper(10, 20, 0x99a3ad, 0xd0d6dc);
    scene.three.add(floor);
    scene.camera = new THREE.PerspectiveCamera(45, box.clientWidth / box.clientHeight, 0.1, 100);
    scene.camera.position.set(5, 6, 8);
    scene.camera.lookAt(0.8, 0, 1.2);
    scene.meshes = new Map();
    scene.ready = true;
  }
  const shapes = {
    station: () => new THREE.BoxGeometry(1.0, 0.05, 1.0),
    buffer: () => new THREE.BoxGeometry(0.4, 0.3, 0.4),
    "mobile-robot": () => new THREE.CylinderGeometry(0.25, 0.25, 0.3, 24),
    arm: () => new THREE.CylinderGeometry(0.05, 0.07, 0.5, 12),
  };
  // Where a body is at sim time t: along the segment of its move it is on (docs/dashboard.md).
  function poseAt(b, t) {
    const m = b.motion;
    let from = b.pose, to = b.pose, f = 0;
    if (m && t < m.t[m.t.length - 1]) {
      let i = 1;
      while (i < m.t.length - 1 && t >= m.t[i]) ++i;
      from = m.poses[i - 1];
      to = m.poses[i];
      f = t <= m.t[i - 1] ? 0 : (t - m.t[i - 1]) / (m.t[i] - m.t[i - 1]);
    }
    const q = new THREE.Quaternion(from[4], from[5], from[6], from[3]);
    q.slerp(new THREE.Quaternion(to[4], to[5], to[6], to[3]), f);
    const p = new THREE.Vector3(from[0], from[1], from[2]).lerp(new THREE.Vector3(to[0], to[1], to[2]), f);
    return { p, q };
  }
  function meshOf(id, make) {
    let mesh = scene.meshes.get(id);
    if (!mesh) {
      mesh = new THREE.Mesh(make(), new THREE.MeshLambertMaterial());
      scene.meshes.set(id, mesh);
      scene.three.add(mesh);
    }
    mesh.userData.drawn = true;
    return mesh;
  }
  // The resources where their capabilities place them, and the bodies of the physical cell
  // where cell-sim has them: a mobile robot where its base is, the tables and grippers as
  // their boxes, each part as a small cube in its order's colour (its mesh stays in the cell).
  function renderScene(s, t) {
    if (!scene.ready) return;
    for (const mesh of scene.meshes.values()) mesh.userData.drawn = false;
    const bases = new Map();
    const parts = {};  // order -> its parts in the cell
    for (const b of s.bodies || []) {
      if (b.mesh) parts[b.order] = (parts[b.order] || 0) + 1;
      const size = b.half_extents;
      if (!b.mesh && size.every((h) => h === 0)) {
        if (b.owner) bases.set(b.owner, b);
        continue;
      }
      const { p, q } = poseAt(b, t);
      const mesh = meshOf("body:" + b.id, () => b.mesh ? new THREE.BoxGeometry(0.04, 0.04, 0.04)
                                                    : new THREE.BoxGeometry(2 * size[0], 2 * size[1], 2 * size[2]));
      mesh.position.copy(p);
      mesh.quaternion.copy(q);
      mesh.material.color.set(b.mesh ? "hsl(" + hue(b.order) + ", 65%, 45%)" : b.owner.startsWith("station") ? 0xb8c0c8 : 0x455a64);
    }
    for (const [order, n] of Object.entries(parts)) page.parts[order] = Math.max(page.parts[order] || 0, n);
    if (!scene.framed) frame(s.resources.filter((r) => r.position).map((r) => new THREE.Vector3(...r.position)));
    for (const r of s.resources) {
      if (!r.position || !shapes[r.kind]) continue;
      const mesh = meshOf(r.id, shapes[r.kind]);
      const lift = r.kind === "arm" ? 0.25 : r.kind === "station" ? -0.025 : 0.15;
      const base = bases.get(r.id);
      const at = base ? poseAt(base, t).p : new THREE.Vector3(...r.position);
      mesh.position.set(at.x, at.y + lift, at.z);
      mesh.material.color.set(!r.alive ? 0xb00020 : r.out_of_service ? 0x5f6368 : r.busy ? 0x0b5cad : r.kind === "station" ? 0x9aa5b1 : 0x2e7d32);
    }
    for (const [id, mesh] of scene.meshes) {
      if (mesh.userData.drawn) continue;
      scene.three.remove(mesh);
      mesh.geometry.dispose();
      mesh.material.dispose();
      scene.meshes.delete(id);
    }
    scene.renderer.render(scene.three, scene.camera);
    document.body.dataset.scene = "drawn";
  }
  // The camera takes in the whole cell, from above and in front, once it knows where it is.
  function frame(places) {
    if (!places.length) return;
    const box = new THREE.Box3().setFromPoints(places);
    const centre = box.getCenter(new THREE.Vector3());
    const reach = Math.max(1, box.getSize(new THREE.Vector3()).length() / 2);
    scene.camera.position.set(centre.x + 1.1 * reach, centre.y + 1.6 * reach, centre.z + 2.0 * reach);
    scene.camera.lookAt(centre);
    scene.framed = true;
  }
  // Drawn when the view changed, and while something moves, at most ten times a second (in
  // software a frame takes milliseconds to tens of them, the first up to a second).
  function drawScene() {
    const s = page.state;
    if (!scene.ready || !s || scene.nextFrame) return;
    const again = () => { scene.nextFrame = setTimeout(() => { scene.nextFrame = null; drawScene(); }, 100); };
    if (Date.now() - (scene.drawnAt || 0) < 100) return again();
    const t = simNow();
    const moving = (s.bodies || []).some((b) => b.motion && t < b.motion.t[b.motion.t.length - 1]);
    const key = JSON.stringify([s.resources.map((r) => [r.id, r.alive, r.busy, r.out_of_service, r.position]), s.bodies]);
    if (key === scene.key && !moving && !scene.wasMoving) return;
    scene.key = key;
    scene.wasMoving = moving;
    scene.drawnAt = Date.now();
    timed("scene", () => renderScene(s, t));
    if (moving) {
      page.movingFrames += 1;
      again();
    }
  }

  // The tables at once, the 3D view at most ten times a second (drawScene), the chart, which
  // takes longer to draw, at most every quarter of a second (the newest state then).
  let slowDrawn = 0, slowPending = false;
  function drawSlow() {
    slowPending = false;
    slowDrawn = Date.now();
    timed("gantt", renderGantt);
  }
  // How long each part of the page takes to draw (ms, the last 1000), for docs/performance.md.
  function timed(part, draw) {
    const began = performance.now();
    draw();
    const times = page.drawMs[part];
    times.push(performance.now() - began);
    if (times.length > 1000) times.shift();
  }
  function render(s) {
    timed("tables", () => {
      document.getElementById("domain").textContent = "on domain " + s.domain;
      renderAttention(s.attention);
      renderResources(s.resources);
      renderOrders(s.orders);
      renderInventory(s.inventory);
      renderAlarms(s.alarms);
    });
    // After this frame is painted: the tables' change is on the screen before the 3D view's draw.
    setTimeout(drawScene, 0);
    if (slowPending) return;
    slowPending = true;
    setTimeout(drawSlow, Math.max(0, slowDrawn + 250 - Date.now()));
  }

  function follow() {
    const events = new EventSource("/events");
    const link = document.getElementById("link");
    events.onopen = () => { link.textContent = "live"; link.className = "link-up"; };
    events.onerror = () => { link.textContent = "reconnecting"; link.className = "link-down"; };
    events.addEventListener("bar", (e) => {
      page.bars.push(JSON.parse(e.data));
      if (page.bars.length > 20000) page.bars.splice(0, page.bars.length - 20000);
    });
    // States that come faster than the page draws are drawn once, the newest, at the next frame.
    let drawing = false;
    events.addEventListener("state", (e) => {
      page.state = JSON.parse(e.data);
      page.states += 1;
      receivedAt = Date.now() / 1000;
      if (page.state.heard_at > lastHeard && lastHeard > 0) page.received.push(receivedAt - page.state.heard_at);
      if (drawing) return;
      drawing = true;
      requestAnimationFrame(() => {
        drawing = false;
        const s = page.state;
        render(s);
        // How old the change it shows is, once drawn (the first state's change may be old).
        if (s.heard_at > lastHeard) {
          if (lastHeard > 0) {
            page.latencies.push(Date.now() / 1000 - s.heard_at);
            page.built.push(s.built_at - s.heard_at);  // of which cellctl up's part
          }
          lastHeard = s.heard_at;
        }
      });
    });
  }

  // What the cell answered an action: its JSON's message, or its plain text.
  async function messageOf(response) {
    const text = await response.text();
    try { return JSON.parse(text).message; } catch (ignored) { return text; }
  }
  // An operator's action (POST, `body` if any): the answer, or the refusal's reason, under the form.
  async function act(url, body) {
    const answer = document.getElementById("submit-answer");
    try {
      const response = await fetch(url, { method: "POST", body });
      answer.textContent = await messageOf(response);
      answer.className = response.ok ? "answer-ok" : "answer-refused";
    } catch (error) {
      answer.textContent = "the cell did not answer: " + error.message;
      answer.className = "answer-refused";
    }
  }
  // An order from a product's zip, through the cell's desk (POST /orders): the answer, or the
  // refusal's reason, under the form.
  function takeOrders() {
    const form = document.getElementById("submit-form");
    const answer = document.getElementById("submit-answer");
    form.addEventListener("submit", async (e) => {
      e.preventDefault();
      const file = document.getElementById("submit-file").files[0];
      const id = document.getElementById("submit-id").value.trim();
      const button = document.getElementById("submit-button");
      button.disabled = true;
      answer.className = "";
      answer.textContent = "sending " + file.name + "...";
      try {
        const response = await fetch("/orders" + (id ? "?order=" + encodeURIComponent(id) : ""),
                                     { method: "POST", body: file, headers: { "Content-Type": "application/zip" } });
        answer.textContent = await messageOf(response);
        answer.className = response.ok ? "answer-ok" : "answer-refused";
        if (response.ok) form.reset();
      } catch (error) {
        answer.textContent = "the cell did not answer: " + error.message;
        answer.className = "answer-refused";
      } finally {
        button.disabled = false;
      }
    });
  }

  takeOrders();
  follow();
  // The 3D view once the page has loaded: its WebGL context (software GL on a machine without
  // a GPU: a GPU process to start) no longer holds back the tables, which say what needs
  // attention first. On a starved machine that start took seconds, and a test's 30 s.
  window.addEventListener("load", () => setTimeout(() => {
    startScene();
    drawScene();
  }, 0));
  setInterval(() => {
    if (!page.state) return;
    document.getElementById("clock").textContent = "sim " + simNow().toFixed(1) + " s";
    timed("gantt", renderGantt);
  }, 1000);
})();
