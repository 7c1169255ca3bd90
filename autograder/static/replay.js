// The report's replay: in each figure of a world, a slider over simulation time moves the
// robot, shows its last lidar scan (rays and points; none while the lidar was silent) and
// the command in force, and fades the collisions still to come.  It reads only the figure's own JSON; nothing is fetched.
"use strict";
(() => {
  const SPEED = 2; // sim seconds per wall second while playing
  const num = (v) => v.toFixed(3);

  // The last index whose row's time (row[0]) is at or before t, or -1.
  function before(rows, t) {
    let lo = 0, hi = rows.length - 1, found = -1;
    while (lo <= hi) {
      const mid = (lo + hi) >> 1;
      if (rows[mid][0] <= t + 1e-9) { found = mid; lo = mid + 1; } else { hi = mid - 1; }
    }
    return found;
  }

  // [x, y, theta] at time t, between the samples around it.
  function poseAt(poses, t) {
    const i = before(poses, t);
    if (i < 0) return poses[0].slice(1);
    if (i >= poses.length - 1) return poses[poses.length - 1].slice(1);
    const [t0, x0, y0, a0] = poses[i];
    const [t1, x1, y1, a1] = poses[i + 1];
    const f = t1 > t0 ? (t - t0) / (t1 - t0) : 0;
    const turn = Math.atan2(Math.sin(a1 - a0), Math.cos(a1 - a0));
    return [x0 + (x1 - x0) * f, y0 + (y1 - y0) * f, a0 + turn * f];
  }

  // The command in the robot's frame: an arrow for linear.x, an arc for angular.z.
  function commandPath(v, w, radius) {
    let d = "";
    if (Math.abs(v) > 0.005) {
      const s = Math.sign(v), x0 = s * radius, x1 = x0 + v * 0.6, head = 0.05 * s;
      d += `M${num(x0)},0L${num(x1)},0M${num(x1 - head)},0.035L${num(x1)},0` +
           `L${num(x1 - head)},-0.035`;
    }
    if (Math.abs(w) > 0.005) {
      const r = radius + 0.05, sweep = Math.max(-2.8, Math.min(2.8, w * 0.6));
      d += `M${num(r)},0A${num(r)},${num(r)} 0 0 ${sweep > 0 ? 1 : 0} ` +
           `${num(r * Math.cos(sweep))},${num(r * Math.sin(sweep))}`;
    }
    return d;
  }

  function setUp(figure) {
    const runs = JSON.parse(figure.querySelector("script.replay-data").textContent);
    const svg = figure.querySelector("svg.sim-trajectory");
    const layer = svg.querySelector("g.replay");
    const robot = layer.querySelector(".replay-robot");
    const radius = Number(robot.querySelector("circle").getAttribute("r"));
    const arrow = layer.querySelector(".replay-command");
    const rays = layer.querySelector(".replay-rays");
    const points = layer.querySelector(".replay-scan");
    const controls = figure.querySelector(".replay-controls");
    const slider = controls.querySelector(".replay-time");
    const clock = controls.querySelector(".replay-clock");
    const said = controls.querySelector(".replay-said");
    const picker = controls.querySelector(".replay-run");
    const play = controls.querySelector(".replay-play");
    const groups = [...svg.querySelectorAll("g.run")];
    let index = 0;
    let playing = null;

    function collisionsOf(i) {
      return groups.length ? groups[i].querySelectorAll(".collision")
                           : svg.querySelectorAll(".collision");
    }

    function draw() {
      const run = runs[index];
      const t = Number(slider.value);
      clock.textContent = clock.dataset.format.replace("{seconds}", t.toFixed(2));
      groups.forEach((g, i) => g.setAttribute("opacity", i === index ? "1" : "0.3"));
      if (!run.poses.length) { layer.setAttribute("visibility", "hidden"); return; }
      layer.setAttribute("visibility", "visible");
      const [x, y, a] = poseAt(run.poses, t);
      robot.setAttribute("transform",
                         `translate(${num(x)} ${num(y)}) rotate(${(a * 180 / Math.PI).toFixed(2)})`);
      const c = before(run.commands, t);
      const [v, w] = c < 0 ? [0, 0] : run.commands[c].slice(1);
      said.textContent = `v ${v.toFixed(2)} m/s, ω ${w.toFixed(2)} rad/s`;
      arrow.setAttribute("d", commandPath(v, w, radius));
      const s = before(run.scans, t);
      let dots = "", lines = "";
      if (s >= 0 && t - run.scans[s][0] <= 1.5 * run.scan_every) {
        const [ts, ranges] = run.scans[s];
        const [sx, sy, sa] = poseAt(run.poses, ts);
        ranges.forEach((range, i) => {
          if (range === null) return;
          const b = sa + run.scan.angle_min + i * run.scan.angle_increment;
          const px = num(sx + range * Math.cos(b)), py = num(sy + range * Math.sin(b));
          dots += `M${px},${py}h0`;
          lines += `M${num(sx)},${num(sy)}L${px},${py}`;
        });
      }
      points.setAttribute("d", dots);
      rays.setAttribute("d", lines);
      for (const mark of collisionsOf(index)) {
        mark.setAttribute("opacity", Number(mark.dataset.t) <= t + 1e-9 ? "1" : "0.25");
      }
    }

    function choose(i) {
      index = i;
      slider.max = String(runs[i].end);
      if (Number(slider.value) > runs[i].end) slider.value = String(runs[i].end);
      draw();
    }

    function stop() {
      if (playing !== null) cancelAnimationFrame(playing);
      playing = null;
      play.textContent = play.dataset.play;
    }

    function start() {
      if (Number(slider.value) >= runs[index].end) slider.value = "0";
      let last = null;
      const frame = (now) => {
        if (last !== null) {
          const t = Math.min(runs[index].end, Number(slider.value) + (now - last) / 1000 * SPEED);
          slider.value = String(t);
          draw();
          if (t >= runs[index].end) { stop(); return; }
        }
        last = now;
        playing = requestAnimationFrame(frame);
      };
      play.textContent = play.dataset.pause;
      playing = requestAnimationFrame(frame);
    }

    slider.addEventListener("input", () => { stop(); draw(); });
    if (picker) picker.addEventListener("change", () => { stop(); choose(Number(picker.value)); });
    play.addEventListener("click", () => (playing === null ? start() : stop()));
    controls.hidden = false;
    choose(0);
  }

  for (const figure of document.querySelectorAll("figure.world")) {
    if (figure.querySelector("script.replay-data")) setUp(figure);
  }
})();
