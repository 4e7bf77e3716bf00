// The 3D view of a case: click a row of the results table (or open `?view=<test>-<method>`). Left:
// the rest mesh, or another method of the same test; right: the case. Both share one camera
// (drag to turn, wheel to zoom, "reset"). Colours: shaded with the fixed region blue and the handles
// red, or per face the angle error (RMS change of its corner angles, 0-10 degrees) or the area
// distortion (x0.5 blue to x2 red), both against the rest mesh. Drawn on a 2D canvas, back to
// front (painter's algorithm): no WebGL needed, so it draws the same in every browser and headless.
// Meshes load per case from viewer/*.js (report/viewer.rs), not with the page.
(function () {
  'use strict';
  var box = document.getElementById('viewer');
  if (!box) return;
  var canvases = [document.getElementById('viewer-left-canvas'), document.getElementById('viewer-right-canvas')];
  var colourBy = document.getElementById('viewer-colour');
  var leftChoice = document.getElementById('viewer-left');
  var title = document.getElementById('viewer-title');
  var data = {}, waiting = {};
  var camera = { yaw: 0.6, pitch: -0.35, zoom: 1 };
  var shown = null; // { rest, right, left, title }

  // viewer/<name>.js calls this with its base64 arrays.
  window.deformbenchViewerData = function (name, fields) {
    data[name] = fields;
    (waiting[name] || []).forEach(function (f) { f(); });
    delete waiting[name];
  };
  function load(name, done) {
    if (data[name]) { done(); return; }
    if (waiting[name]) { waiting[name].push(done); return; }
    waiting[name] = [done];
    var s = document.createElement('script');
    s.src = 'viewer/' + encodeURIComponent(name) + '.js';
    s.onerror = function () { title.textContent = 'could not load ' + s.src; };
    document.body.appendChild(s);
  }
  function bytes(b64) {
    var text = atob(b64), out = new Uint8Array(text.length);
    for (var i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
    return out.buffer;
  }
  function decoded(name, key, Type) {
    var d = data[name];
    d.decoded = d.decoded || {};
    if (!d.decoded[key]) d.decoded[key] = new Type(bytes(d[key]));
    return d.decoded[key];
  }
  // The file's positions: u16 per coordinate between its lo and hi corners (report/viewer.rs).
  function positionsOf(name) {
    var d = data[name];
    if (!d.positionsF32) {
      var q = decoded(name, 'positions', Uint16Array), p = new Float32Array(q.length);
      for (var i = 0; i < q.length; i++) {
        var k = i % 3;
        p[i] = d.lo[k] + (d.hi[k] - d.lo[k]) * q[i] / 65535;
      }
      d.positionsF32 = p;
    }
    return d.positionsF32;
  }

  // Per face: its three corner angles (radians) and its area, of positions p on triangles t.
  function faceGeometry(p, t) {
    var n = t.length / 3, angles = new Float32Array(3 * n), areas = new Float32Array(n);
    for (var f = 0; f < n; f++) {
      var v = [t[3 * f], t[3 * f + 1], t[3 * f + 2]];
      for (var c = 0; c < 3; c++) {
        var a = v[c], b = v[(c + 1) % 3], d = v[(c + 2) % 3];
        var ux = p[3 * b] - p[3 * a], uy = p[3 * b + 1] - p[3 * a + 1], uz = p[3 * b + 2] - p[3 * a + 2];
        var wx = p[3 * d] - p[3 * a], wy = p[3 * d + 1] - p[3 * a + 1], wz = p[3 * d + 2] - p[3 * a + 2];
        var dot = ux * wx + uy * wy + uz * wz;
        var cx = uy * wz - uz * wy, cy = uz * wx - ux * wz, cz = ux * wy - uy * wx;
        var cross = Math.sqrt(cx * cx + cy * cy + cz * cz);
        angles[3 * f + c] = Math.atan2(cross, dot);
        if (c === 0) areas[f] = 0.5 * cross;
      }
    }
    return { angles: angles, areas: areas };
  }

  // A colour ramp from blue (s = 0) through white (0.5) to red (1).
  function ramp(s) {
    s = Math.max(0, Math.min(1, s));
    return s < 0.5 ? [255 * 2 * s, 255 * 2 * s, 255] : [255, 255 * 2 * (1 - s), 255 * 2 * (1 - s)];
  }

  // Face colours of `positions` (the rest mesh when it is the rest) for the chosen colouring.
  function faceColours(positions, isRest) {
    var rest = shown.rest, t = rest.triangles, n = t.length / 3, out = new Array(n);
    var mode = colourBy.value;
    if (mode === 'shaded' || isRest) {
      for (var f = 0; f < n; f++) {
        var r0 = rest.roles[t[3 * f]], r1 = rest.roles[t[3 * f + 1]], r2 = rest.roles[t[3 * f + 2]];
        out[f] = r0 === 1 && r1 === 1 && r2 === 1 ? [110, 150, 235]
          : r0 === 2 && r1 === 2 && r2 === 2 ? [235, 110, 100] : [205, 205, 200];
      }
      return out;
    }
    var g = faceGeometry(positions, t);
    for (var h = 0; h < n; h++) {
      if (mode === 'angle') {
        var s2 = 0;
        for (var c = 0; c < 3; c++) { var e = g.angles[3 * h + c] - rest.geometry.angles[3 * h + c]; s2 += e * e; }
        out[h] = ramp(0.5 + 0.5 * Math.sqrt(s2 / 3) * 180 / Math.PI / 10);
      } else {
        out[h] = ramp(0.5 + 0.5 * Math.log2(g.areas[h] / rest.geometry.areas[h]));
      }
    }
    return out;
  }

  // Draw `positions` with `colours` per face on `canvas` from the shared camera.
  function draw(canvas, positions, colours, label) {
    var ctx = canvas.getContext('2d'), w = canvas.width, h = canvas.height;
    var rest = shown.rest, t = rest.triangles, n = t.length / 3;
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(0, 0, w, h);
    var cy = Math.cos(camera.yaw), sy = Math.sin(camera.yaw), cp = Math.cos(camera.pitch), sp = Math.sin(camera.pitch);
    var scale = camera.zoom * 0.45 * Math.min(w, h) / rest.radius;
    var m = positions.length / 3, x = new Float32Array(m), y = new Float32Array(m), z = new Float32Array(m);
    for (var i = 0; i < m; i++) {
      var px = positions[3 * i] - rest.center[0], py = positions[3 * i + 1] - rest.center[1];
      var pz = positions[3 * i + 2] - rest.center[2];
      var rx = cy * px + sy * py, ry = -sy * px + cy * py;  // turn about z (the shapes' long axis)
      var up = cp * pz - sp * ry, depth = sp * pz + cp * ry;  // then tilt towards the viewer
      x[i] = w / 2 + scale * rx; y[i] = h / 2 - scale * up; z[i] = depth;
    }
    var order = new Uint32Array(n), depthOf = new Float32Array(n);
    for (var f = 0; f < n; f++) {
      order[f] = f;
      depthOf[f] = z[t[3 * f]] + z[t[3 * f + 1]] + z[t[3 * f + 2]];
    }
    order.sort(function (a, b) { return depthOf[b] - depthOf[a]; });  // far first
    for (var k = 0; k < n; k++) {
      var g = order[k], a = t[3 * g], b = t[3 * g + 1], c = t[3 * g + 2];
      // Flat shading by the screen-space normal's facing (both sides lit).
      var ux = x[b] - x[a], uy = y[b] - y[a], uz = z[b] - z[a], vx = x[c] - x[a], vy = y[c] - y[a], vz = z[c] - z[a];
      var nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      var len = Math.sqrt(nx * nx + ny * ny + nz * nz) || 1;
      var light = 0.35 + 0.65 * Math.abs(nz / len);
      var col = colours[g];
      ctx.fillStyle = 'rgb(' + (col[0] * light | 0) + ',' + (col[1] * light | 0) + ',' + (col[2] * light | 0) + ')';
      ctx.strokeStyle = ctx.fillStyle;
      ctx.beginPath();
      ctx.moveTo(x[a], y[a]); ctx.lineTo(x[b], y[b]); ctx.lineTo(x[c], y[c]);
      ctx.closePath();
      ctx.fill();
      ctx.stroke();  // closes the hairline gaps between neighbours
    }
    ctx.fillStyle = '#222';
    ctx.font = '14px sans-serif';
    ctx.fillText(label, 8, 18);
  }

  // The number of pixels that differ from the white background (the browser test reads it).
  function drawnPixels(canvas) {
    var pixels = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data, count = 0;
    for (var i = 0; i < pixels.length; i += 4) {
      if (pixels[i] < 250 || pixels[i + 1] < 250 || pixels[i + 2] < 250) count++;
    }
    return count;
  }

  function redraw() {
    if (!shown) return;
    var leftIsRest = !shown.left;
    var leftPositions = leftIsRest ? shown.rest.positions : shown.left.positions;
    // Colours change with the colouring, not with the camera: computed once per choice.
    if (shown.colouredBy !== colourBy.value) {
      shown.colours = [faceColours(leftPositions, leftIsRest), faceColours(shown.right.positions, false)];
      shown.colouredBy = colourBy.value;
    }
    draw(canvases[0], leftPositions, shown.colours[0], leftIsRest ? 'rest' : shown.left.method);
    draw(canvases[1], shown.right.positions, shown.colours[1], shown.right.method);
    box.dataset.pixels = Math.min(drawnPixels(canvases[0]), drawnPixels(canvases[1]));
  }

  function restMesh(name) {
    var d = data[name];
    if (!d.mesh) {
      var p = positionsOf(name), lo = [1e30, 1e30, 1e30], hi = [-1e30, -1e30, -1e30];
      for (var i = 0; i < p.length; i++) { lo[i % 3] = Math.min(lo[i % 3], p[i]); hi[i % 3] = Math.max(hi[i % 3], p[i]); }
      var t = decoded(name, 'triangles', d.index_bytes === 2 ? Uint16Array : Uint32Array);
      d.mesh = {
        positions: p, triangles: t, roles: decoded(name, 'roles', Uint8Array),
        center: [0, 1, 2].map(function (k) { return (lo[k] + hi[k]) / 2; }),
        radius: 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1,
        // A sheet (the bumpy plane, thin in z) is seen from above; the rest from the side.
        pitch: hi[2] - lo[2] < 0.3 * Math.max(hi[0] - lo[0], hi[1] - lo[1]) ? -1.1 : -0.35,
        geometry: faceGeometry(p, t)
      };
    }
    return d.mesh;
  }

  // Open the view of the row `row` (a results-table row with data-view).
  function open(row, leftMethod) {
    var started = performance.now();
    var scenario = row.dataset.scenario, restName = row.dataset.rest;
    var others = Array.prototype.filter.call(document.querySelectorAll('#results-table tbody tr[data-view]'),
      function (r) { return r.dataset.scenario === scenario && r !== row; });
    leftChoice.textContent = '';
    leftChoice.add(new Option('rest', ''));
    others.forEach(function (r) { leftChoice.add(new Option(r.dataset.method, r.dataset.view)); });
    var left = others.filter(function (r) { return r.dataset.method === leftMethod; })[0];
    leftChoice.value = left ? left.dataset.view : '';
    box.hidden = false;
    title.textContent = scenario + ': ' + row.dataset.method + ' (loading)';
    load(restName, function () {
      load(row.dataset.view, function () {
        var finish = function () {
          shown = {
            rest: restMesh(restName),
            right: { method: row.dataset.method, positions: positionsOf(row.dataset.view) },
            left: left ? { method: left.dataset.method, positions: positionsOf(left.dataset.view) } : null
          };
          if (box.dataset.rest !== restName) camera = { yaw: 0.6, pitch: shown.rest.pitch, zoom: 1 };
          box.dataset.rest = restName;
          title.textContent = scenario + ': ' + row.dataset.method;
          redraw();
          box.dataset.loadMs = Math.round(performance.now() - started);
          box.dataset.view = row.dataset.view;
          box.dataset.left = left ? left.dataset.method : 'rest';
        };
        if (left) load(left.dataset.view, finish); else finish();
      });
    });
  }

  document.querySelectorAll('#results-table tbody tr[data-view]').forEach(function (row) {
    row.classList.add('viewable');
    row.addEventListener('click', function () { open(row); box.scrollIntoView(); });
  });
  leftChoice.addEventListener('change', function () {
    var current = document.querySelector('#results-table tbody tr[data-view="' + box.dataset.view + '"]');
    var other = document.querySelector('#results-table tbody tr[data-view="' + leftChoice.value + '"]');
    if (current) open(current, other ? other.dataset.method : null);
  });
  colourBy.addEventListener('change', redraw);
  document.getElementById('viewer-reset').addEventListener('click', function () {
    camera = { yaw: 0.6, pitch: shown ? shown.rest.pitch : -0.35, zoom: 1 }; redraw();
  });
  document.getElementById('viewer-close').addEventListener('click', function () { box.hidden = true; });
  // One camera for both canvases: drag turns, the wheel zooms.
  canvases.forEach(function (canvas) {
    var last = null;
    canvas.addEventListener('mousedown', function (e) { last = [e.clientX, e.clientY]; });
    window.addEventListener('mouseup', function () { last = null; });
    canvas.addEventListener('mousemove', function (e) {
      if (!last) return;
      camera.yaw += 0.01 * (e.clientX - last[0]);
      camera.pitch = Math.max(-1.5, Math.min(1.5, camera.pitch + 0.01 * (e.clientY - last[1])));
      last = [e.clientX, e.clientY];
      redraw();
    });
    canvas.addEventListener('wheel', function (e) {
      e.preventDefault();
      camera.zoom *= e.deltaY < 0 ? 1.15 : 1 / 1.15;
      redraw();
    }, { passive: false });
  });

  var params = new URLSearchParams(window.location.search);
  if (params.get('colour')) colourBy.value = params.get('colour');
  var asked = params.get('view') &&
    document.querySelector('#results-table tbody tr[data-view="' + CSS.escape(params.get('view')) + '"]');
  if (asked) open(asked, params.get('left'));
})();
