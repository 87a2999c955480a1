// The 3D view's script (reflector_opt.report.view3d): draws the scene's meshes on a 2D
// canvas, flat-shaded, far triangles first, at the pose the sliders choose. Every number it
// draws comes from the scene: the model's Rx and Ry at the slider values, the Eq 3 and axial
// distances and the beams' end points at each pose. With scene.live (stream --view) it draws
// the units stacked instead, each posed by the newest message of the page's WebSocket (the
// package's Rx·Ry of each unit), and the pose is the newest message's. Kept free of template braces.
(function () {
  "use strict";
  var root = document.currentScript.parentElement;
  var scene = JSON.parse(root.querySelector(".view3d-data").textContent);
  var canvas = root.querySelector("canvas");
  var context = canvas.getContext("2d");
  var sliders = {
    pitch: root.querySelector("input[name=pitch]"),
    roll: root.querySelector("input[name=roll]"),
  };
  var shown = {
    pitch: root.querySelector("output[name=pitch]"),
    roll: root.querySelector("output[name=roll]"),
  };
  var live = scene.live, centre = scene.centre_mm;
  var identity = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  var readout = root.querySelector(".view3d-readout");
  var camera = { azimuth: scene.azimuth_deg + 25, elevation: 12, zoom: 1 };
  var light = normalised([-0.4, 0.5, 0.75]);

  function bytes(text) {
    var raw = atob(text);
    var out = new Uint8Array(raw.length);
    for (var i = 0; i < raw.length; i++) out[i] = raw.charCodeAt(i);
    return out.buffer;
  }
  function floats(text) { return new Float32Array(bytes(text)); }
  function normalised(v) {
    var n = Math.hypot(v[0], v[1], v[2]);
    return [v[0] / n, v[1] / n, v[2] / n];
  }
  function rgb(hex) {
    return [1, 3, 5].map(function (i) { return parseInt(hex.slice(i, i + 2), 16); });
  }
  function product(a, b) {
    return a.map(function (row) {
      return [0, 1, 2].map(function (j) {
        return row[0] * b[0][j] + row[1] * b[1][j] + row[2] * b[2][j];
      });
    });
  }

  var meshes = scene.meshes.map(function (m) {
    return { rotating: m.rotating, colour: rgb(m.colour), vertices: floats(m.vertices),
             faces: new Uint32Array(bytes(m.faces)) };
  });
  var poses = {
    distance: floats(scene.distance_mm), axial: floats(scene.axial_mm),
    hit: floats(scene.hit_mm), nearest: floats(scene.nearest_mm),
  };
  var sensorCount = scene.sensors.length;

  // The chain of tip_pose: unit k's body in F_k = R_1⋯R_(k-1) at c_k, its turning parts in
  // F_k·R_k; c_(k+1) = c_k + L·(F_k·R_k)·z. The tip is c_(n+1).
  function chain(message) {
    var base = identity, at = [0, 0, 0], placed = [];
    message.rotations.forEach(function (r) {
      var turned = product(base, r);
      placed.push({ base: base, turn: turned, at: at });
      at = [0, 1, 2].map(function (x) { return at[x] + live.link_mm * turned[x][2]; });
      base = turned;
    });
    return { counter: message.counter, angles_deg: message.angles_deg, placed: placed,
             rotation: base, tip_mm: at };
  }
  var newest = live && chain({ counter: null, angles_deg: [],
    rotations: Array.apply(null, Array(live.units)).map(function () { return identity; }) });

  function pose() {
    if (live) return newest;
    var i = Number(sliders.pitch.value), j = Number(sliders.roll.value);
    // R = Rx(roll)·Ry(pitch), paper Eq 1, from the model's own matrices
    return { i: i, j: j, pitch_deg: scene.pitch_deg[i], roll_deg: scene.roll_deg[j],
             rotation: product(scene.rx[j], scene.ry[i]) };
  }

  function basis() {
    var az = camera.azimuth * Math.PI / 180, el = camera.elevation * Math.PI / 180;
    var eye = [Math.cos(el) * Math.cos(az), Math.cos(el) * Math.sin(az), Math.sin(el)];
    var right = [-Math.sin(az), Math.cos(az), 0];
    var up = [eye[1] * right[2] - eye[2] * right[1], eye[2] * right[0] - eye[0] * right[2],
              eye[0] * right[1] - eye[1] * right[0]];
    return [right, up, eye];
  }

  // A point of the base frame (mm) in camera coordinates: right, up, towards the eye.
  function toCamera(frame, p) {
    return frame.map(function (b) {
      return b[0] * (p[0] - centre[0]) + b[1] * (p[1] - centre[1]) + b[2] * (p[2] - centre[2]);
    });
  }

  function projector() {
    var w = canvas.width, h = canvas.height;
    var s = camera.zoom * Math.min(w, h) / (2.4 * scene.extent_mm);
    return function (c) { return [w / 2 + s * c[0], h / 2 - s * c[1]]; };
  }

  // Each mesh of each placed unit ({base, turn, at}: its frames and its rotation centre).
  function facing(frame, placed) {
    var triangles = [];
    placed.forEach(function (p) { meshes.forEach(function (m) {
      var whole = product(frame, m.rotating ? p.turn : p.base), v = m.vertices, n = v.length / 3;
      var shift = toCamera(frame, p.at), cam = new Float64Array(v.length);
      for (var k = 0; k < n; k++) {
        for (var r = 0; r < 3; r++) {
          cam[3 * k + r] = shift[r] + whole[r][0] * v[3 * k] + whole[r][1] * v[3 * k + 1] +
            whole[r][2] * v[3 * k + 2];
        }
      }
      for (var f = 0; f < m.faces.length; f += 3) {
        var a = 3 * m.faces[f], b = 3 * m.faces[f + 1], c = 3 * m.faces[f + 2];
        var u = [cam[b] - cam[a], cam[b + 1] - cam[a + 1], cam[b + 2] - cam[a + 2]];
        var t = [cam[c] - cam[a], cam[c + 1] - cam[a + 1], cam[c + 2] - cam[a + 2]];
        var normal = [u[1] * t[2] - u[2] * t[1], u[2] * t[0] - u[0] * t[2], u[0] * t[1] - u[1] * t[0]];
        if (normal[2] <= 0) continue; // faces away from the eye (closed meshes)
        var shade = 0.35 + 0.65 * Math.max(0, normal[0] * light[0] + normal[1] * light[1] +
          normal[2] * light[2]) / Math.hypot(normal[0], normal[1], normal[2]);
        triangles.push({ depth: cam[a + 2] + cam[b + 2] + cam[c + 2], colour: m.colour, shade: shade,
                         points: [[cam[a], cam[a + 1]], [cam[b], cam[b + 1]], [cam[c], cam[c + 1]]] });
      }
    }); });
    return triangles.sort(function (p, q) { return p.depth - q.depth; });
  }

  function line(project, frame, from, to, colour, dashed) {
    var p = project(toCamera(frame, from)), q = project(toCamera(frame, to));
    context.strokeStyle = colour;
    context.lineWidth = 2 * (window.devicePixelRatio || 1);
    context.setLineDash(dashed ? [6, 4] : []);
    context.beginPath();
    context.moveTo(p[0], p[1]);
    context.lineTo(q[0], q[1]);
    context.stroke();
    context.setLineDash([]);
    return q;
  }

  function at(array, index) { return [array[3 * index], array[3 * index + 1], array[3 * index + 2]]; }

  function drawBeams(project, frame, current) {
    var words = [];
    scene.sensors.forEach(function (sensor, k) {
      var index = (current.i * scene.roll_deg.length + current.j) * sensorCount + k;
      var d = poses.distance[index], t = poses.axial[index];
      if (isFinite(t)) line(project, frame, sensor.position_mm, at(poses.hit, index), sensor.colour, false);
      line(project, frame, sensor.position_mm, at(poses.nearest, index), sensor.colour, true);
      var p = project(toCamera(frame, sensor.position_mm));
      context.fillStyle = sensor.colour;
      context.font = (13 * (window.devicePixelRatio || 1)) + "px sans-serif";
      var label = sensor.name + "  d = " + d.toFixed(3) + " mm";
      context.lineWidth = 3 * (window.devicePixelRatio || 1);
      context.strokeStyle = "#ffffff";
      context.strokeText(label, p[0] + 8, p[1] - 8);
      context.fillText(label, p[0] + 8, p[1] - 8);
      words.push(sensor.name + ": d = " + d.toFixed(3) + " mm (along the axis " +
        (isFinite(t) ? t.toFixed(3) + " mm" : "missed") + ")");
    });
    return words;
  }

  function draw() {
    var scale = window.devicePixelRatio || 1;
    canvas.width = Math.max(1, Math.round(canvas.clientWidth * scale));
    canvas.height = Math.max(1, Math.round(canvas.clientHeight * scale));
    var current = pose(), frame = basis(), project = projector();
    context.fillStyle = "#ffffff";
    context.fillRect(0, 0, canvas.width, canvas.height);
    var placed = live ? current.placed : [{ base: identity, turn: current.rotation, at: [0, 0, 0] }];
    facing(frame, placed).forEach(function (tri) {
      var c = tri.colour.map(function (x) { return Math.round(x * tri.shade); });
      var style = "rgb(" + c.join(",") + ")";
      var p = tri.points.map(project);
      context.fillStyle = style;
      context.strokeStyle = style;
      context.lineWidth = 0.5;
      context.beginPath();
      context.moveTo(p[0][0], p[0][1]);
      context.lineTo(p[1][0], p[1][1]);
      context.lineTo(p[2][0], p[2][1]);
      context.closePath();
      context.fill();
      context.stroke();
    });
    if (live) {
      line(project, frame, current.placed[live.units - 1].at, current.tip_mm, "#d62728", false);
      readout.textContent = current.counter === null ? "waiting for the stream" : "frame " +
        current.counter + " · " + current.angles_deg.map(function (a, k) {
          return "unit " + (k + 1) + " pitch " + a[0].toFixed(2) + "°, roll " + a[1].toFixed(2) + "°";
        }).join(" · ") + " · tip (" + current.tip_mm.map(function (x) { return x.toFixed(2); }).join(", ") + ") mm";
      return;
    }
    var words = drawBeams(project, frame, current);
    shown.pitch.textContent = current.pitch_deg.toFixed(1) + "°";
    shown.roll.textContent = current.roll_deg.toFixed(1) + "°";
    readout.textContent = "pitch " + current.pitch_deg.toFixed(1) + "°, roll " +
      current.roll_deg.toFixed(1) + "° · " + words.join(" · ");
  }

  if (live) { // the newest message only, drawn once a frame of the browser's at most
    var waiting = false;
    var socket = new WebSocket("ws://" + location.host + live.path);
    socket.onmessage = function (event) {
      newest = chain(JSON.parse(event.data));
      if (!waiting) {
        waiting = true;
        requestAnimationFrame(function () { waiting = false; draw(); });
      }
    };
    socket.onclose = function () { readout.textContent += " · the stream has ended"; };
  } else {
    sliders.pitch.addEventListener("input", draw);
    sliders.roll.addEventListener("input", draw);
  }
  var dragging = null;
  canvas.addEventListener("pointerdown", function (e) {
    dragging = [e.clientX, e.clientY];
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener("pointermove", function (e) {
    if (!dragging) return;
    camera.azimuth -= 0.5 * (e.clientX - dragging[0]);
    camera.elevation = Math.max(-89, Math.min(89, camera.elevation + 0.5 * (e.clientY - dragging[1])));
    dragging = [e.clientX, e.clientY];
    draw();
  });
  canvas.addEventListener("pointerup", function () { dragging = null; });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    camera.zoom = Math.max(0.3, Math.min(8, camera.zoom * Math.exp(-0.001 * e.deltaY)));
    draw();
  }, { passive: false });
  window.addEventListener("resize", draw);
  root.view3d = { pose: pose, draw: draw };
  draw();
})();
