// The 3D view's script (reflector_opt.report.view3d): draws the scene's meshes on a 2D
// canvas, flat-shaded, far triangles first, at the pose the sliders choose. Every number it
// draws comes from the scene: the model's Rx and Ry at the slider values, the Eq 3 and axial
// distances and the beams' end points at each pose. Kept free of template braces.
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

  function pose() {
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

  // A point of the unit frame (mm) in camera coordinates: right, up, towards the eye.
  function toCamera(frame, p) {
    return frame.map(function (b) { return b[0] * p[0] + b[1] * p[1] + b[2] * p[2]; });
  }

  function projector() {
    var w = canvas.width, h = canvas.height;
    var s = camera.zoom * Math.min(w, h) / (2.4 * scene.extent_mm);
    return function (c) { return [w / 2 + s * c[0], h / 2 - s * c[1]]; };
  }

  function facing(frame, turn) {
    var triangles = [];
    meshes.forEach(function (m) {
      var whole = m.rotating ? product(frame, turn) : frame, v = m.vertices, n = v.length / 3;
      var cam = new Float64Array(v.length);
      for (var k = 0; k < n; k++) {
        for (var r = 0; r < 3; r++) {
          cam[3 * k + r] = whole[r][0] * v[3 * k] + whole[r][1] * v[3 * k + 1] + whole[r][2] * v[3 * k + 2];
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
    });
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
    facing(frame, current.rotation).forEach(function (tri) {
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
    var words = drawBeams(project, frame, current);
    shown.pitch.textContent = current.pitch_deg.toFixed(1) + "°";
    shown.roll.textContent = current.roll_deg.toFixed(1) + "°";
    readout.textContent = "pitch " + current.pitch_deg.toFixed(1) + "°, roll " +
      current.roll_deg.toFixed(1) + "° · " + words.join(" · ");
  }

  sliders.pitch.addEventListener("input", draw);
  sliders.roll.addEventListener("input", draw);
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
