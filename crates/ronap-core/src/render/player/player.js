"use strict";
// The ronap episode player: reads each section's packed episode (see render/player/mod.rs),
// draws it on its canvas and keeps every section on one timeline. No network: everything the
// page needs is in the page.
(function () {
  const $ = (id) => document.getElementById(id);

  function bytesOf(base64) {
    const text = atob(base64.trim());
    const out = new Uint8Array(text.length);
    for (let i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
    return out;
  }

  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // The columns of the packed bytes, each value's bytes gathered back from their planes.
  function columns(raw, list) {
    const out = {};
    let at = 0;
    for (const [name, width, n] of list) {
      const planes = raw.subarray(at, at + width * n);
      at += width * n;
      if (width === 1) {
        out[name] = planes.slice();
      } else if (width === 2) {
        const a = new Uint16Array(n);
        for (let i = 0; i < n; i++) a[i] = planes[i] | (planes[n + i] << 8);
        out[name] = a;
      } else {
        const bytes = new Uint8Array(width * n);
        for (let i = 0; i < n; i++) for (let b = 0; b < width; b++) bytes[width * i + b] = planes[b * n + i];
        out[name] = new Float32Array(bytes.buffer);
      }
    }
    return out;
  }

  // Series of `length` wrapping u16 differences back to values times `quantum`.
  function undelta(deltas, length, quantum) {
    const out = new Float32Array(deltas.length);
    for (let s = 0; s < deltas.length; s += length) {
      let acc = 0;
      for (let i = 0; i < length; i++) {
        acc = (acc + deltas[s + i]) & 0xffff;
        out[s + i] = ((acc << 16) >> 16) * quantum;
      }
    }
    return out;
  }

  const rad = (deg) => (deg * Math.PI) / 180;
  const fmt = (v, digits) => (Number.isFinite(v) ? v.toFixed(digits) : "-");
  // Angles as the step log writes them: 0 to 360 degrees.
  const deg = (v) => fmt(((v % 360) + 360) % 360, 2);
  function faded(hex) {
    const n = parseInt(hex.slice(1), 16);
    const mix = (c) => Math.round((c + 255) / 2);
    return `rgb(${mix(n >> 16)},${mix((n >> 8) & 255)},${mix(n & 255)})`;
  }
  function escapeHtml(s) {
    return String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
  }

  class Player {
    constructor(section) {
      this.section = section;
      this.canvas = section.querySelector("canvas");
      this.panel = section.querySelector(".panel");
      this.meta = JSON.parse(section.querySelector(".ronap-trace").textContent);
      this.view = { scale: 1, ox: 0, oy: 0 };
    }

    async load() {
      const m = this.meta;
      const F = m.frames;
      const q = m.quantum;
      const c = columns(await inflate(bytesOf(this.section.querySelector(".ronap-blob").textContent)), m.columns);
      this.x = undelta(c.x, F, q);
      this.y = undelta(c.y, F, q);
      this.z = undelta(c.z, F, 0.01);
      this.bearing = undelta(c.bearing, F, 0.01);
      this.distance = undelta(c.distance, F, q);
      this.direction = undelta(c.direction, F, 0.01);
      this.readings = undelta(c.readings, F, q);
      this.goal = c.goal;
      this.flags = c.flags;
      this.action = c.action;
      this.reward = c.reward;
      this.speed = c.speed;
      this.turn = c.turn;
      this.moverX = undelta(c.mover_x, F, q);
      this.moverY = undelta(c.mover_y, F, q);
      this.moverFlags = c.mover_flags;
      this.moverGoalX = undelta(c.mover_goal_x, F, q);
      this.moverGoalY = undelta(c.mover_goal_y, F, q);
      // Where each robot's readings start: robot after robot, beam after beam, frame after frame.
      this.readingsAt = [];
      let at = 0;
      for (const r of m.robots) {
        this.readingsAt.push(at);
        at += r.beams.length * F;
      }
      const scene = bytesOf(this.section.querySelector(".ronap-scene").textContent);
      this.background = await createImageBitmap(new Blob([scene], { type: "image/png" }));
    }

    // The canvas pixel of scene point (x, y) in the current view.
    toCanvas(x, y) {
      const v = this.view;
      return [v.ox + x * v.scale, v.oy - y * v.scale];
    }

    resize() {
      const [W, H] = this.meta.scene;
      const dpr = window.devicePixelRatio || 1;
      const width = Math.max(100, Math.round(this.canvas.clientWidth * dpr));
      const most = Math.round(window.innerHeight * 0.75 * dpr);
      const height = Math.max(100, Math.min(Math.round((width * H) / W), most));
      if (this.canvas.width !== width || this.canvas.height !== height) {
        this.canvas.width = width;
        this.canvas.height = height;
      }
    }

    // The view: the whole scene, or zoomed in round the followed robot.
    place(f, followed) {
      const [W, H] = this.meta.scene;
      const cw = this.canvas.width;
      const ch = this.canvas.height;
      const fit = Math.min(cw / W, ch / H);
      const F = this.meta.frames;
      if (followed !== null && followed < this.meta.robots.length) {
        const scale = fit * Math.max(2, Math.min(W, H) / 300);
        const i = followed * F + f;
        this.view = { scale, ox: cw / 2 - this.x[i] * scale, oy: ch / 2 + this.y[i] * scale };
      } else {
        this.view = { scale: fit, ox: (cw - W * fit) / 2, oy: (ch + H * fit) / 2 };
      }
    }

    draw(frame, state) {
      const m = this.meta;
      const F = m.frames;
      const f = Math.min(frame, F - 1);
      const ctx = this.canvas.getContext("2d");
      this.resize();
      this.place(f, state.follow ? state.robot : null);
      const s = this.view.scale;
      const [W, H] = m.scene;
      ctx.fillStyle = "#ddd";
      ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
      // Smoothed, so that walls thinner than a canvas pixel still show.
      ctx.imageSmoothingEnabled = true;
      ctx.imageSmoothingQuality = "high";
      const [bx, by] = this.toCanvas(0, H);
      ctx.drawImage(this.background, bx, by, W * s, H * s);
      const px = (k, g) => this.toCanvas(this.x[k * F + g], this.y[k * F + g]);
      const present = (k, g) => (this.flags[k * F + g] & 1) !== 0;
      const disc = (x, y, r, fill) => {
        ctx.beginPath();
        ctx.arc(x, y, r, 0, 2 * Math.PI);
        ctx.fillStyle = fill;
        ctx.fill();
      };
      const least = Math.max(1.5, 1.5 * (window.devicePixelRatio || 1));
      if (state.goals) {
        m.robots.forEach((r, k) => {
          const reached = this.goal[k * F + f];
          const colour = m.team ? faded(r.colour) : "#1eaa3c";
          r.goals.forEach((g, i) => {
            if (i < reached) return;
            const [gx, gy] = this.toCanvas(g[0], g[1]);
            const radius = Math.max(r.tolerance * s, 3);
            if (i === reached) {
              disc(gx, gy, radius, colour);
            } else {
              ctx.beginPath();
              ctx.arc(gx, gy, radius, 0, 2 * Math.PI);
              ctx.strokeStyle = colour;
              ctx.lineWidth = least;
              ctx.stroke();
            }
            if (r.goals.length > 1) {
              ctx.fillStyle = "#333";
              ctx.font = `${Math.round(10 * (window.devicePixelRatio || 1))}px sans-serif`;
              ctx.fillText(String(i + 1), gx + radius, gy - radius);
            }
          });
        });
      }
      if (state.paths) {
        ctx.lineWidth = least;
        m.robots.forEach((r, k) => {
          ctx.strokeStyle = m.team ? r.colour : "#2850e6";
          ctx.beginPath();
          for (let g = 0; g <= f; g++) {
            const [x, y] = px(k, g);
            if (g === 0) ctx.moveTo(x, y);
            else ctx.lineTo(x, y);
          }
          ctx.stroke();
        });
      }
      const movers = m.movers.length;
      const moverAt = (i, g) => this.toCanvas(this.moverX[i * F + g], this.moverY[i * F + g]);
      if (state.tracks) {
        ctx.strokeStyle = "#fad2aa";
        ctx.lineWidth = least;
        for (let i = 0; i < movers; i++) {
          ctx.beginPath();
          let open = false;
          for (let g = 0; g <= f; g++) {
            if ((this.moverFlags[i * F + g] & 1) === 0) {
              open = false;
              continue;
            }
            const [x, y] = moverAt(i, g);
            if (open) ctx.lineTo(x, y);
            else ctx.moveTo(x, y);
            open = true;
          }
          ctx.stroke();
        }
      }
      for (let i = 0; i < movers; i++) {
        const flags = this.moverFlags[i * F + f];
        if ((flags & 1) === 0) continue;
        const [x, y] = moverAt(i, f);
        const body = m.movers[i];
        if (m.mover_goals && flags & 2 && state.goals) {
          const [gx, gy] = this.toCanvas(this.moverGoalX[i * F + f], this.moverGoalY[i * F + f]);
          ctx.strokeStyle = "rgba(235,120,20,0.45)";
          ctx.lineWidth = 1;
          ctx.beginPath();
          ctx.moveTo(x, y);
          ctx.lineTo(gx, gy);
          ctx.moveTo(gx - 4, gy - 4);
          ctx.lineTo(gx + 4, gy + 4);
          ctx.moveTo(gx - 4, gy + 4);
          ctx.lineTo(gx + 4, gy - 4);
          ctx.stroke();
        }
        ctx.fillStyle = "#eb7814";
        if (body.disc !== undefined) {
          disc(x, y, Math.max(body.disc * s, 1.5), "#eb7814");
        } else {
          const [hw, hh] = body.box;
          ctx.fillRect(x - hw * s, y - hh * s, 2 * hw * s, 2 * hh * s);
        }
      }
      if (state.laser) {
        ctx.lineWidth = 1;
        m.robots.forEach((r, k) => {
          if (!present(k, f)) return;
          if (m.robots.length > 10 && k !== state.robot) return;
          const x0 = this.x[k * F + f];
          const y0 = this.y[k * F + f];
          const z = this.z[k * F + f];
          const [cx, cy] = this.toCanvas(x0, y0);
          r.beams.forEach((offset, b) => {
            const d = this.readings[this.readingsAt[k] + b * F + f];
            const a = rad(z + offset);
            const [ex, ey] = this.toCanvas(x0 + Math.cos(a) * d, y0 + Math.sin(a) * d);
            ctx.strokeStyle = d > 0.6 * r.range ? "#28be3c" : d > 0.3 * r.range ? "#ebbe14" : "#e12828";
            ctx.beginPath();
            ctx.moveTo(cx, cy);
            ctx.lineTo(ex, ey);
            ctx.stroke();
          });
        });
      }
      m.robots.forEach((r, k) => {
        if (!present(k, f)) return;
        const [x, y] = px(k, f);
        const radius = Math.max(r.radius * s, 2.5);
        const colour = m.team ? r.colour : "#2850e6";
        const a = rad(this.z[k * F + f]);
        ctx.strokeStyle = colour;
        ctx.lineWidth = Math.max(2, radius / 3);
        ctx.beginPath();
        ctx.moveTo(x, y);
        ctx.lineTo(x + Math.cos(a) * radius * 2, y - Math.sin(a) * radius * 2);
        ctx.stroke();
        if (r.outline) {
          // A rectangle or polygon footprint: its corners turned by the heading.
          const c = Math.cos(a), n = Math.sin(a);
          ctx.fillStyle = colour;
          ctx.beginPath();
          r.outline.forEach(([ahead, left], i) => {
            const vx = x + (c * ahead - n * left) * s, vy = y - (n * ahead + c * left) * s;
            if (i === 0) ctx.moveTo(vx, vy); else ctx.lineTo(vx, vy);
          });
          ctx.closePath();
          ctx.fill();
        } else {
          disc(x, y, radius, colour);
        }
        if (k === state.robot && m.robots.length > 1) {
          ctx.strokeStyle = "#000";
          ctx.lineWidth = least;
          ctx.beginPath();
          ctx.arc(x, y, radius + 3 * least, 0, 2 * Math.PI);
          ctx.stroke();
        }
      });
      this.showPanel(f, Math.min(state.robot, m.robots.length - 1));
    }

    showPanel(f, k) {
      const m = this.meta;
      const F = m.frames;
      const i = k * F + f;
      const r = m.robots[k];
      const flags = this.flags[i];
      const last = f === F - 1;
      const code = this.action[i];
      const acted = code !== 0xffff;
      const action = !acted
        ? last ? "none: the episode ended" : "none: it no longer acts"
        : code === 0xfffe
          ? `v=${+this.speed[i].toFixed(4)};w=${+this.turn[i].toFixed(4)}`
          : code === 0xfffd
            ? `v=${+this.speed[i].toFixed(4)};steer=${+this.turn[i].toFixed(4)}`
            : m.actions[code] ?? "?";
      const state = (flags & 1) === 0 ? "not in the scene" : (flags & 2) !== 0 ? "running" : "stopped";
      const readings = r.beams.map((_, b) => fmt(this.readings[this.readingsAt[k] + b * F + f], 1));
      const g = Math.min(this.goal[i], r.goals.length - 1);
      const rows = [
        ["step", `${f} of ${F - 1}`],
        ["robot", `<span class="swatch" style="background:${m.team ? r.colour : "#2850e6"}"></span>${k}${m.robots.length > 1 ? ` of ${m.robots.length}` : ""} (${state})`],
        ["pose", `x ${fmt(this.x[i], 2)}, y ${fmt(this.y[i], 2)}, heading ${deg(this.z[i])}&deg;`],
        ["action", `<b class="action">${escapeHtml(action)}</b>`],
        ["reward", acted ? fmt(this.reward[i], 4) : "-"],
        ["collided", acted ? ((flags & 4) !== 0 ? '<b class="hit">yes</b>' : "no") : "-"],
        ["goal", `${this.goal[i]} of ${r.goals.length} reached; heading for (${fmt(r.goals[g][0], 1)}, ${fmt(r.goals[g][1], 1)})`],
        ["distance D", `${fmt(this.distance[i], 2)} px`],
        ["bearing &theta;", `${deg(this.bearing[i])}&deg;`],
        ["direction", `${deg(this.direction[i])}&deg;`],
        ["laser d<sub>1</sub>..d<sub>" + r.beams.length + "</sub>", `<span class="readings">${readings.join(" ")}</span>`],
      ];
      this.panel.innerHTML =
        "<table>" + rows.map(([key, v]) => `<tr><th>${key}</th><td>${v}</td></tr>`).join("") + "</table>" +
        '<p class="hint">the observation as the step log holds it: the laser readings, &theta;, D and direction; ' +
        "the action is the one taken from this step's state, its reward and collision what it led to</p>";
    }
  }

  const state = { frame: 0, playing: false, robot: 0, follow: false, laser: true, tracks: true, paths: true, goals: true };
  const players = Array.from(document.querySelectorAll("section.player")).map((s) => new Player(s));
  let frames = 1;

  function draw() {
    for (const p of players) p.draw(state.frame, state);
    $("scrub").value = String(state.frame);
    $("frame").textContent = `step ${state.frame} of ${frames - 1}`;
    $("play").innerHTML = state.playing ? "&#10074;&#10074;" : "&#9654;";
  }
  function go(frame) {
    state.frame = Math.max(0, Math.min(frames - 1, frame));
    draw();
  }
  let clock = null;
  function tick(now) {
    if (!state.playing) return;
    if (clock === null) clock = now;
    const speed = Number($("speed").value);
    const due = Math.floor(((now - clock) / 1000) * speed);
    if (due > 0) {
      clock += (due * 1000) / speed;
      if (state.frame + due >= frames - 1) {
        state.playing = false;
        go(frames - 1);
        return;
      }
      go(state.frame + due);
    }
    requestAnimationFrame(tick);
  }
  function playPause() {
    if (!state.playing && state.frame >= frames - 1) state.frame = 0;
    state.playing = !state.playing;
    clock = null;
    draw();
    if (state.playing) requestAnimationFrame(tick);
  }
  function robots() {
    return Math.max(...players.map((p) => p.meta.robots.length));
  }
  function followNext() {
    if (state.follow) state.robot = (state.robot + 1) % robots();
    state.follow = true;
    $("follow").checked = true;
    $("robot").value = String(state.robot);
    draw();
  }

  async function start() {
    await Promise.all(players.map((p) => p.load()));
    frames = Math.max(...players.map((p) => p.meta.frames));
    $("scrub").max = String(frames - 1);
    const select = $("robot");
    for (let k = 0; k < robots(); k++) {
      const o = document.createElement("option");
      o.value = String(k);
      o.textContent = String(k);
      select.appendChild(o);
    }
    $("scrub").addEventListener("input", (e) => go(Number(e.target.value)));
    $("play").addEventListener("click", playPause);
    $("back").addEventListener("click", () => go(state.frame - 1));
    $("forward").addEventListener("click", () => go(state.frame + 1));
    select.addEventListener("change", (e) => {
      state.robot = Number(e.target.value);
      draw();
    });
    for (const name of ["follow", "laser", "tracks", "paths", "goals"]) {
      $(name).addEventListener("change", (e) => {
        state[name] = e.target.checked;
        draw();
      });
    }
    document.addEventListener("keydown", (e) => {
      if (e.target instanceof HTMLSelectElement || e.ctrlKey || e.metaKey || e.altKey) return;
      const keys = {
        " ": playPause,
        ArrowLeft: () => go(state.frame - (e.shiftKey ? 10 : 1)),
        ArrowRight: () => go(state.frame + (e.shiftKey ? 10 : 1)),
        Home: () => go(0),
        End: () => go(frames - 1),
        f: followNext,
      };
      const act = keys[e.key];
      if (act) {
        e.preventDefault();
        act();
      }
    });
    window.addEventListener("resize", draw);
    draw();
    window.ronap.ready = true;
  }

  window.ronap = { players, state, go, ready: false, error: null };
  start().catch((e) => {
    window.ronap.error = String(e);
    document.body.insertAdjacentHTML("afterbegin", `<p class="error">cannot play: ${escapeHtml(e)}</p>`);
  });
})();
