// The 3D view of a case: click a row of the results table (or open `?view=<test>-<method>`). Left:
// the rest mesh, or another method of the same test; right: the case. Both share one camera
// (drag to turn, wheel to zoom, "reset"). Colours: shaded with the fixed region blue and the handles
// red, or per face the angle error (RMS change of its corner angles, 0-10 degrees) or the area
// distortion (x0.5 blue to x2 red), both against the rest mesh. Clicking a view names the vertex
// under the pointer, with its role or the error of the faces around it, in both views.
// Drawn with WebGL 2 where the browser has it: the faces and their colours go to the GPU once per
// case and colouring, and a redraw while turning only changes the camera: even on a software GPU
// (SwiftShader, headless Chromium on 2 cores) two views of a million faces each redraw in about
// 0.7 s, and 0.23-0.32 s while turning with the coarser copy (below) at 1-4.3M faces. Where getContext('webgl2') gives nothing (or with `renderer=canvas` in the address) a 2D
// canvas draws instead, sorting and filling every face per redraw (painter's algorithm): the same
// picture, in about 0.1 s at ten thousand faces a view, 0.6 s at 80K, 8 s at a million.
// Meshes load per case from viewer/*.js (report/viewer.rs), not with the page.
// For the browser tests and for measuring, the view's box (#viewer) carries data-renderer, data-view,
// data-left, data-pixels (non-background pixels of the smaller view), data-checksum (of both
// pictures), data-centre (the left view's centre pixel), data-load-ms (opening to first picture),
// data-redraw-ms (the last redraw, GPU work included) and, after `spin=N` in the address, data-spin-ms
// (the median of N redraws turning 0.05 rad each, drawn as a drag draws them), data-turning-faces
// (the faces a view draws while turning: all of them, or a coarser copy's above `turning=N`,
// default 300,000) and data-turning-pixels (data-pixels of the last turning redraw); `yaw=` turns the first picture and `pick=x,y` clicks the right view there.
(function () {
  'use strict';
  var box = document.getElementById('viewer');
  if (!box) return;
  var canvases = [document.getElementById('viewer-left-canvas'), document.getElementById('viewer-right-canvas')];
  var names = [document.getElementById('viewer-left-name'), document.getElementById('viewer-right-name')];
  var pickLabels = [document.getElementById('viewer-left-pick'), document.getElementById('viewer-right-pick')];
  var colourBy = document.getElementById('viewer-colour');
  var leftChoice = document.getElementById('viewer-left');
  var title = document.getElementById('viewer-title');
  var params = new URLSearchParams(window.location.search);
  var data = {}, waiting = {};
  var camera = { yaw: 0.6, pitch: -0.35, zoom: 1 };
  // { rest, views: [left, right] each { method, positions, isRest, errors }, reach, colouredBy, picked }
  var shown = null;
  var renderers = null;  // one per canvas, made when a case first opens

  // ---- The case's files.

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

  // A view of the file `name`: its positions as numbers and as the file gives them (u16 between
  // lo and hi, which the GPU unpacks itself: half the memory of floats).
  function viewOf(name, method, isRest) {
    var d = data[name];
    return { method: method, positions: positionsOf(name), isRest: isRest,
      packed: { values: decoded(name, 'positions', Uint16Array), lo: d.lo, hi: d.hi } };
  }

  function restMesh(name) {
    var d = data[name];
    if (!d.mesh) {
      var p = positionsOf(name), lo = [1e30, 1e30, 1e30], hi = [-1e30, -1e30, -1e30];
      for (var i = 0; i < p.length; i++) { lo[i % 3] = Math.min(lo[i % 3], p[i]); hi[i % 3] = Math.max(hi[i % 3], p[i]); }
      d.mesh = {
        positions: p, triangles: decoded(name, 'triangles', d.index_bytes === 2 ? Uint16Array : Uint32Array),
        roles: decoded(name, 'roles', Uint8Array),
        center: [0, 1, 2].map(function (k) { return (lo[k] + hi[k]) / 2; }),
        radius: 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1,
        // A sheet (the bumpy plane, thin in z) is seen from above; the rest from the side.
        pitch: hi[2] - lo[2] < 0.3 * Math.max(hi[0] - lo[0], hi[1] - lo[1]) ? -1.1 : -0.35,
        geometry: null  // faceGeometry, the first time an error colouring asks for it
      };
    }
    return d.mesh;
  }

  // While turning, a mesh of more than `turningFaces` faces is drawn from a coarser copy, and the
  // full mesh again once the pointer is let go: a software GPU's redraw costs about 0.3 us per face
  // drawn, and a drag needs a picture every few tenths of a second. The copy clusters the rest
  // mesh's vertices on a grid (the first vertex of each occupied cell stands for the cell) and keeps
  // one face per triple of distinct cells that faces join, with the colour of the first: closed
  // where the mesh is (no holes, unlike drawing every k-th face), on the same vertices, so every view
  // of the test uses it with its own positions. `turning=N` in the address sets the threshold.
  var turningFaces = parseInt(params.get('turning'), 10) || 300000;
  function turningMesh(rest) {
    if (rest.turning !== undefined) return rest.turning;
    var t = rest.triangles, n = t.length / 3, p = rest.positions, nv = p.length / 3;
    rest.turning = null;
    if (n <= turningFaces) return null;
    var lo = [1e30, 1e30, 1e30], hi = [-1e30, -1e30, -1e30];
    for (var i = 0; i < p.length; i++) { lo[i % 3] = Math.min(lo[i % 3], p[i]); hi[i % 3] = Math.max(hi[i % 3], p[i]); }
    var size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
    var cellOf = new Int32Array(nv);
    // A surface occupies about c N^2 cells of an N^3 grid and a clustered surface has about twice as
    // many faces as cells: one trial grid, then the one that gives about half turningFaces cells.
    function cluster(cells) {
      var first = new Map(), rep = new Int32Array(nv), h = size / cells;
      for (var v = 0; v < nv; v++) {
        var key = (Math.floor((p[3 * v] - lo[0]) / h) * (cells + 1) + Math.floor((p[3 * v + 1] - lo[1]) / h)) * (cells + 1) +
          Math.floor((p[3 * v + 2] - lo[2]) / h);
        var r = first.get(key);
        if (r === undefined) { r = v; first.set(key, v); }
        rep[v] = r;
      }
      return { rep: rep, occupied: first.size };
    }
    var trial = cluster(64), cells = Math.max(8, Math.round(64 * Math.sqrt(turningFaces / 2 / trial.occupied)));
    var rep = cluster(cells).rep, kept = new Map(), triangles = [], faces = [];
    for (var f = 0; f < n; f++) {
      var a = rep[t[3 * f]], b = rep[t[3 * f + 1]], c = rep[t[3 * f + 2]];
      if (a === b || b === c || c === a) continue;
      var x = Math.min(a, b, c), z = Math.max(a, b, c), y = a + b + c - x - z, key = x * nv + y;
      var seen = kept.get(key);
      if (seen === undefined) kept.set(key, [z]); else if (seen.indexOf(z) >= 0) continue; else seen.push(z);
      triangles.push(a, b, c);
      faces.push(f);
    }
    if (triangles.length / 3 >= n) return null;
    rest.turning = { triangles: new Uint32Array(triangles), faces: new Uint32Array(faces) };
    return rest.turning;
  }

  // The colours of the turning mesh's faces: each its first face's.
  function turningColours(turning, colours) {
    var out = new Uint8Array(3 * turning.faces.length);
    for (var f = 0; f < turning.faces.length; f++) {
      var o = 3 * turning.faces[f];
      out[3 * f] = colours[o]; out[3 * f + 1] = colours[o + 1]; out[3 * f + 2] = colours[o + 2];
    }
    return out;
  }

  // The farthest any shown point lies from the rest mesh's centre: the depth range the GPU keeps
  // (a result may reach beyond the rest mesh's bounding sphere).
  function reachOf(center, positionSets) {
    var r2 = 0;
    positionSets.forEach(function (p) {
      for (var i = 0; i < p.length; i += 3) {
        var x = p[i] - center[0], y = p[i + 1] - center[1], z = p[i + 2] - center[2];
        r2 = Math.max(r2, x * x + y * y + z * z);
      }
    });
    return Math.sqrt(r2) || 1;
  }

  // ---- Errors and colours, per face.

  // Per face: its three corner angles (radians) and its area, of positions p on triangles t.
  // Twice the area is the length of the cross product of any two of its edges, whichever corner
  // they leave from, so one cross product serves all three angles.
  function faceGeometry(p, t) {
    var n = t.length / 3, angles = new Float32Array(3 * n), areas = new Float32Array(n);
    for (var f = 0; f < n; f++) {
      var a = 3 * t[3 * f], b = 3 * t[3 * f + 1], c = 3 * t[3 * f + 2];
      var abx = p[b] - p[a], aby = p[b + 1] - p[a + 1], abz = p[b + 2] - p[a + 2];
      var bcx = p[c] - p[b], bcy = p[c + 1] - p[b + 1], bcz = p[c + 2] - p[b + 2];
      var cax = p[a] - p[c], cay = p[a + 1] - p[c + 1], caz = p[a + 2] - p[c + 2];
      var nx = aby * bcz - abz * bcy, ny = abz * bcx - abx * bcz, nz = abx * bcy - aby * bcx;
      var twice = Math.sqrt(nx * nx + ny * ny + nz * nz);
      angles[3 * f] = Math.atan2(twice, -(abx * cax + aby * cay + abz * caz));
      angles[3 * f + 1] = Math.atan2(twice, -(bcx * abx + bcy * aby + bcz * abz));
      angles[3 * f + 2] = Math.atan2(twice, -(cax * bcx + cay * bcy + caz * bcz));
      areas[f] = 0.5 * twice;
    }
    return { angles: angles, areas: areas };
  }

  function restGeometry(rest) {
    if (!rest.geometry) rest.geometry = faceGeometry(rest.positions, rest.triangles);
    return rest.geometry;
  }

  // Per face of a result: the RMS change of its corner angles (degrees) and its area over its rest area.
  function faceErrors(positions) {
    var rest = shown.rest, before = restGeometry(rest), after = faceGeometry(positions, rest.triangles);
    var n = after.areas.length, angle = new Float32Array(n), area = new Float32Array(n);
    for (var f = 0; f < n; f++) {
      var s2 = 0;
      for (var c = 0; c < 3; c++) { var e = after.angles[3 * f + c] - before.angles[3 * f + c]; s2 += e * e; }
      angle[f] = Math.sqrt(s2 / 3) * 180 / Math.PI;
      area[f] = after.areas[f] / before.areas[f];
    }
    return { angle: angle, area: area, areas: after.areas };
  }

  // A colour ramp from blue (s = 0) through white (0.5) to red (1), into out[3i..3i+2].
  function ramp(s, out, i) {
    s = Math.max(0, Math.min(1, s));
    var lo = 255 * 2 * s, hi = 255 * 2 * (1 - s);
    out[3 * i] = s < 0.5 ? lo : 255; out[3 * i + 1] = s < 0.5 ? lo : hi; out[3 * i + 2] = s < 0.5 ? 255 : hi;
  }

  // Per face: blue when all its corners are fixed, red when all are handles, else grey.
  function regionColours(rest) {
    var t = rest.triangles, n = t.length / 3, out = new Uint8Array(3 * n), r = rest.roles;
    for (var f = 0; f < n; f++) {
      var r0 = r[t[3 * f]], r1 = r[t[3 * f + 1]], r2 = r[t[3 * f + 2]];
      var col = r0 === 1 && r1 === 1 && r2 === 1 ? [110, 150, 235]
        : r0 === 2 && r1 === 2 && r2 === 2 ? [235, 110, 100] : [205, 205, 200];
      out[3 * f] = col[0]; out[3 * f + 1] = col[1]; out[3 * f + 2] = col[2];
    }
    return out;
  }

  // The face colours (RGB bytes, 3 per face) of a view for the chosen colouring; the rest mesh
  // has no error, so it shows its regions.
  function faceColours(view) {
    var mode = colourBy.value;
    if (mode === 'shaded' || view.isRest) return regionColours(shown.rest);
    if (!view.errors) view.errors = faceErrors(view.positions);
    var values = view.errors[mode], n = values.length, out = new Uint8Array(3 * n);
    for (var f = 0; f < n; f++) {
      ramp(mode === 'angle' ? 0.5 + 0.5 * values[f] / 10 : 0.5 + 0.5 * Math.log2(values[f]), out, f);
    }
    return out;
  }

  // ---- The camera.

  // The shared camera on a canvas: a mesh point p maps to `rows` (p - center) = (right, up, away),
  // turned about z (the shapes' long axis) and tilted towards the viewer, times `scale` pixels.
  function cameraView(canvas) {
    var cy = Math.cos(camera.yaw), sy = Math.sin(camera.yaw), cp = Math.cos(camera.pitch), sp = Math.sin(camera.pitch);
    var scale = camera.zoom * 0.45 * Math.min(canvas.width, canvas.height) / shown.rest.radius;
    return {
      rows: [cy, sy, 0, sp * sy, -sp * cy, cp, -cp * sy, cp * cy, sp],
      center: shown.rest.center, scale: scale, width: canvas.width, height: canvas.height,
      depthRange: scale * shown.reach * 1.01 + 1
    };
  }

  // Every vertex of `positions` in canvas pixels (x right, y down) and depth (pixels, far is larger).
  function projectAll(view, positions) {
    var r = view.rows, c = view.center, s = view.scale, w2 = view.width / 2, h2 = view.height / 2;
    var m = positions.length / 3, x = new Float32Array(m), y = new Float32Array(m), z = new Float32Array(m);
    for (var i = 0; i < m; i++) {
      var px = positions[3 * i] - c[0], py = positions[3 * i + 1] - c[1], pz = positions[3 * i + 2] - c[2];
      x[i] = w2 + s * (r[0] * px + r[1] * py + r[2] * pz);
      y[i] = h2 - s * (r[3] * px + r[4] * py + r[5] * pz);
      z[i] = s * (r[6] * px + r[7] * py + r[8] * pz);
    }
    return { x: x, y: y, z: z };
  }

  // Vertex i alone, as projectAll: [x, y].
  function projectOne(view, positions, i) {
    return [0, 1].map(function (k) {
      var r = view.rows, c = view.center, s = view.scale * (k ? -1 : 1);
      var v = (k ? view.height : view.width) / 2;
      for (var j = 0; j < 3; j++) v += s * r[3 * k + j] * (positions[3 * i + j] - c[j]);
      return v;
    });
  }

  // The camera as a column-major 4x4 matrix from packed positions (0..1 between corners lo and hi)
  // to camera space in pixels (x right, y up, z away).
  function cameraMatrix(view, lo, hi) {
    var r = view.rows, c = view.center, s = view.scale, m = new Float32Array(16);
    for (var k = 0; k < 3; k++) {
      for (var j = 0; j < 3; j++) m[4 * j + k] = s * r[3 * k + j] * (hi[j] - lo[j]);
      m[12 + k] = s * (r[3 * k] * (lo[0] - c[0]) + r[3 * k + 1] * (lo[1] - c[1]) + r[3 * k + 2] * (lo[2] - c[2]));
    }
    m[15] = 1;
    return m;
  }

  // ---- The 2D canvas renderer (no WebGL): every face sorted and filled per redraw.

  function canvasRenderer(canvas) {
    var ctx = canvas.getContext('2d'), mesh = null, colours = null, coarse = null, coarseColours = null;
    return {
      kind: 'canvas',
      setMesh: function (view, triangles, turning) {
        mesh = { positions: view.positions, triangles: triangles };
        coarse = turning ? { positions: view.positions, triangles: turning.triangles, faces: turning.faces } : null;
      },
      setColours: function (c) { colours = c; coarseColours = coarse ? turningColours(coarse, c) : null; },
      draw: function (view, turning) {
        if (turning && coarse) paintFaces(ctx, view, coarse, coarseColours); else paintFaces(ctx, view, mesh, colours);
      },
      // Reading a pixel waits for the drawing to land, so a redraw's time is the real one.
      finish: function () { ctx.getImageData(0, 0, 1, 1); },
      image: function () { return ctx.getImageData(0, 0, canvas.width, canvas.height).data; },
      faceAt: function (view, x, y) { return faceUnder(projectAll(view, mesh.positions), mesh.triangles, x, y); }
    };
  }

  // Fill the faces far to near, each flat shaded by how squarely it faces the viewer (both sides lit).
  function paintFaces(ctx, view, mesh, colours) {
    var t = mesh.triangles, n = t.length / 3, q = projectAll(view, mesh.positions), x = q.x, y = q.y, z = q.z;
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(0, 0, view.width, view.height);
    var order = new Uint32Array(n), depthOf = new Float32Array(n);
    for (var f = 0; f < n; f++) {
      order[f] = f;
      depthOf[f] = z[t[3 * f]] + z[t[3 * f + 1]] + z[t[3 * f + 2]];
    }
    order.sort(function (a, b) { return depthOf[b] - depthOf[a]; });  // far first
    for (var k = 0; k < n; k++) {
      var g = order[k], a = t[3 * g], b = t[3 * g + 1], c = t[3 * g + 2];
      var ux = x[b] - x[a], uy = y[b] - y[a], uz = z[b] - z[a], vx = x[c] - x[a], vy = y[c] - y[a], vz = z[c] - z[a];
      var nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      var len = Math.sqrt(nx * nx + ny * ny + nz * nz) || 1;
      var light = 0.35 + 0.65 * Math.abs(nz / len);
      ctx.fillStyle = 'rgb(' + (colours[3 * g] * light | 0) + ',' + (colours[3 * g + 1] * light | 0) + ',' +
        (colours[3 * g + 2] * light | 0) + ')';
      ctx.strokeStyle = ctx.fillStyle;
      ctx.beginPath();
      ctx.moveTo(x[a], y[a]); ctx.lineTo(x[b], y[b]); ctx.lineTo(x[c], y[c]);
      ctx.closePath();
      ctx.fill();
      ctx.stroke();  // closes the hairline gaps between neighbours
    }
  }

  // The nearest face covering canvas point (px, py) of projected vertices q, or -1: one pass over
  // the faces, on a click only.
  function faceUnder(q, t, px, py) {
    var x = q.x, y = q.y, z = q.z, best = -1, bestDepth = Infinity;
    for (var f = 0; f < t.length / 3; f++) {
      var a = t[3 * f], b = t[3 * f + 1], c = t[3 * f + 2];
      var d = (y[b] - y[c]) * (x[a] - x[c]) + (x[c] - x[b]) * (y[a] - y[c]);
      if (d === 0) continue;
      var la = ((y[b] - y[c]) * (px - x[c]) + (x[c] - x[b]) * (py - y[c])) / d;
      var lb = ((y[c] - y[a]) * (px - x[c]) + (x[a] - x[c]) * (py - y[c])) / d;
      var lc = 1 - la - lb;
      if (la < 0 || lb < 0 || lc < 0) continue;
      var depth = la * z[a] + lb * z[b] + lc * z[c];
      if (depth < bestDepth) { bestDepth = depth; best = f; }
    }
    return best;
  }

  // ---- The WebGL 2 renderer: the faces live on the GPU, a redraw sets the camera and draws.

  var DRAW_VERTEX = [
    '#version 300 es',
    'uniform mat4 camera;  // packed mesh point -> camera space in pixels (x right, y up, z away)',
    'uniform vec3 toClip;  // camera space -> clip space: 2/width, 2/height, 1/depth range',
    'layout(location = 0) in vec3 position;  // 0..1 between the file\'s corners',
    'layout(location = 1) in vec4 colour;',
    'out vec3 seen;',
    'flat out vec4 faceColour;',
    'void main() {',
    '  vec4 p = camera * vec4(position, 1.0);',
    '  seen = p.xyz;',
    '  faceColour = colour;',
    '  gl_Position = vec4(p.xyz * toClip, 1.0);',
    '}'].join('\n');
  // The face's normal is the cross product of how its camera-space position changes across the
  // screen: flat shading with no normals stored, lit as the 2D renderer lights it.
  var DRAW_FRAGMENT = [
    '#version 300 es',
    'precision highp float;',
    'in vec3 seen;',
    'flat in vec4 faceColour;',
    'out vec4 colour;',
    'void main() {',
    '  vec3 n = cross(dFdx(seen), dFdy(seen));',
    '  float len = length(n);',
    '  float light = len > 0.0 ? 0.35 + 0.65 * abs(n.z) / len : 1.0;',
    '  colour = vec4(faceColour.rgb * light, 1.0);',
    '}'].join('\n');
  // Picking draws each face's number (plus one; 0 is the background) into an integer image.
  var PICK_VERTEX = [
    '#version 300 es',
    'uniform mat4 camera;',
    'uniform vec3 toClip;',
    'layout(location = 0) in vec3 position;',
    'flat out uint face;',
    'void main() {',
    '  face = uint(gl_VertexID / 3) + 1u;',
    '  gl_Position = vec4((camera * vec4(position, 1.0)).xyz * toClip, 1.0);',
    '}'].join('\n');
  var PICK_FRAGMENT = [
    '#version 300 es',
    'precision highp float;',
    'precision highp int;',
    'flat in uint face;',
    'layout(location = 0) out uint id;',
    'void main() { id = face; }'].join('\n');

  function compiled(gl, vertex, fragment) {
    var program = gl.createProgram();
    [[gl.VERTEX_SHADER, vertex], [gl.FRAGMENT_SHADER, fragment]].forEach(function (s) {
      var shader = gl.createShader(s[0]);
      gl.shaderSource(shader, s[1]);
      gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS) && !gl.isContextLost()) {
        throw new Error('viewer shader: ' + gl.getShaderInfoLog(shader));
      }
      gl.attachShader(program, shader);
    });
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS) && !gl.isContextLost()) {
      throw new Error('viewer program: ' + gl.getProgramInfoLog(program));
    }
    return { program: program, camera: gl.getUniformLocation(program, 'camera'),
      toClip: gl.getUniformLocation(program, 'toClip') };
  }

  // Flat shading gives each face its own colour, so a corner shared by faces of different colours
  // cannot be one vertex: the triangles are unrolled into three corners per face.
  function cornerPositions(positions, t) {
    var out = new positions.constructor(3 * t.length);
    for (var k = 0; k < t.length; k++) {
      var v = 3 * t[k];
      out[3 * k] = positions[v]; out[3 * k + 1] = positions[v + 1]; out[3 * k + 2] = positions[v + 2];
    }
    return out;
  }
  function cornerColours(colours) {
    var n = colours.length / 3, out = new Uint8Array(12 * n);
    for (var f = 0; f < n; f++) {
      for (var c = 0; c < 3; c++) {
        var o = 12 * f + 4 * c;
        out[o] = colours[3 * f]; out[o + 1] = colours[3 * f + 1]; out[o + 2] = colours[3 * f + 2]; out[o + 3] = 255;
      }
    }
    return out;
  }

  function webglRenderer(canvas, gl, restored) {
    var w = canvas.width, h = canvas.height, gpu = null, source = {}, corners = 0, coarseCorners = 0;
    // Everything the GPU holds; made again if the browser takes the context away and gives it back.
    function setUp() {
      gpu = {
        draw: compiled(gl, DRAW_VERTEX, DRAW_FRAGMENT), pick: compiled(gl, PICK_VERTEX, PICK_FRAGMENT),
        full: shape(), coarse: shape(), ids: gl.createFramebuffer()
      };
      // The face-number image for picking: 32-bit face numbers with their own depth test.
      gl.bindFramebuffer(gl.FRAMEBUFFER, gpu.ids);
      [[gl.R32UI, gl.COLOR_ATTACHMENT0], [gl.DEPTH_COMPONENT24, gl.DEPTH_ATTACHMENT]].forEach(function (a) {
        var store = gl.createRenderbuffer();
        gl.bindRenderbuffer(gl.RENDERBUFFER, store);
        gl.renderbufferStorage(gl.RENDERBUFFER, a[0], w, h);
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, a[1], gl.RENDERBUFFER, store);
      });
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.enable(gl.DEPTH_TEST);
      gl.clearColor(1, 1, 1, 1);
    }
    // A vertex array of u16 corner positions and RGBA corner colours, each in a buffer of its own.
    function shape() {
      var s = { array: gl.createVertexArray(), positions: gl.createBuffer(), colours: gl.createBuffer() };
      gl.bindVertexArray(s.array);
      gl.bindBuffer(gl.ARRAY_BUFFER, s.positions);
      gl.enableVertexAttribArray(0);
      gl.vertexAttribPointer(0, 3, gl.UNSIGNED_SHORT, true, 0, 0);
      gl.bindBuffer(gl.ARRAY_BUFFER, s.colours);
      gl.enableVertexAttribArray(1);
      gl.vertexAttribPointer(1, 4, gl.UNSIGNED_BYTE, true, 0, 0);
      gl.bindVertexArray(null);
      return s;
    }
    function upload(buffer, array) {
      gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
      gl.bufferData(gl.ARRAY_BUFFER, array, gl.STATIC_DRAW);
    }
    function drawWith(program, view, turning) {
      var coarse = turning && coarseCorners > 0;
      gl.useProgram(program.program);
      gl.uniformMatrix4fv(program.camera, false, cameraMatrix(view, source.packed.lo, source.packed.hi));
      gl.uniform3f(program.toClip, 2 / w, 2 / h, 1 / view.depthRange);
      gl.bindVertexArray(coarse ? gpu.coarse.array : gpu.full.array);
      gl.drawArrays(gl.TRIANGLES, 0, coarse ? coarseCorners : corners);
      gl.bindVertexArray(null);
    }
    var renderer = {
      kind: 'webgl2',
      setMesh: function (view, triangles, turning) {
        if (source.packed && source.packed.values === view.packed.values && source.triangles === triangles) return;
        source.packed = view.packed; source.triangles = triangles; source.turning = turning;
        upload(gpu.full.positions, cornerPositions(view.packed.values, triangles));
        corners = triangles.length;
        upload(gpu.coarse.positions, turning ? cornerPositions(view.packed.values, turning.triangles) : new Uint16Array(0));
        coarseCorners = turning ? turning.triangles.length : 0;
      },
      setColours: function (colours) {
        source.colours = colours;
        upload(gpu.full.colours, cornerColours(colours));
        upload(gpu.coarse.colours, source.turning ? cornerColours(turningColours(source.turning, colours)) : new Uint8Array(0));
      },
      draw: function (view, turning) {
        gl.viewport(0, 0, w, h);
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
        drawWith(gpu.draw, view, turning);
      },
      // Reading a pixel waits for the GPU, so a redraw's time is the real one.
      finish: function () { gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4)); },
      // The picture, top row first as a 2D canvas gives it (valid in the task that drew it).
      image: function () {
        var up = new Uint8Array(4 * w * h), down = new Uint8Array(4 * w * h);
        gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, up);
        for (var row = 0; row < h; row++) down.set(up.subarray(4 * w * (h - 1 - row), 4 * w * (h - row)), 4 * w * row);
        return down;
      },
      // The face drawn at (x, y): the scene drawn once more as face numbers, only that pixel kept.
      faceAt: function (view, x, y) {
        var px = Math.floor(x), py = h - 1 - Math.floor(y), id = new Uint32Array(4);
        if (px < 0 || px >= w || py < 0 || py >= h) return -1;
        gl.bindFramebuffer(gl.FRAMEBUFFER, gpu.ids);
        gl.viewport(0, 0, w, h);
        gl.enable(gl.SCISSOR_TEST);
        gl.scissor(px, py, 1, 1);
        gl.clearBufferuiv(gl.COLOR, 0, new Uint32Array([0, 0, 0, 0]));
        gl.clear(gl.DEPTH_BUFFER_BIT);
        drawWith(gpu.pick, view);
        gl.readPixels(px, py, 1, 1, gl.RGBA_INTEGER, gl.UNSIGNED_INT, id);
        gl.disable(gl.SCISSOR_TEST);
        gl.bindFramebuffer(gl.FRAMEBUFFER, null);
        return id[0] - 1;
      }
    };
    canvas.addEventListener('webglcontextlost', function (e) { e.preventDefault(); });
    canvas.addEventListener('webglcontextrestored', function () {
      var was = source;
      setUp();
      source = {};
      if (was.packed) renderer.setMesh({ packed: was.packed }, was.triangles, was.turning);
      if (was.colours) renderer.setColours(was.colours);
      restored();
    });
    setUp();
    return renderer;
  }

  // Whether WebGL runs on the CPU (SwiftShader, as headless Chromium without a GPU): there
  // multisampling costs 3 to 4 times the redraw, on a GPU next to nothing.
  function softwareWebgl() {
    var gl = document.createElement('canvas').getContext('webgl2');
    if (!gl) return false;
    var info = gl.getExtension('WEBGL_debug_renderer_info');
    var name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    var lose = gl.getExtension('WEBGL_lose_context');
    if (lose) lose.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  }

  // WebGL 2 when both canvases give it, else the 2D canvas.
  function makeRenderers(webgl) {
    var options = { antialias: !(webgl && softwareWebgl()) };
    var contexts = canvases.map(function (c) { return webgl ? c.getContext('webgl2', options) : null; });
    if (contexts[0] && contexts[1]) {
      return contexts.map(function (gl, k) { return webglRenderer(canvases[k], gl, function () { show(); }); });
    }
    // A canvas that gave a WebGL context cannot give a 2D one: a fresh copy takes its place.
    canvases = canvases.map(function (c) {
      var copy = c.cloneNode(false);
      c.parentNode.replaceChild(copy, c);
      return copy;
    });
    return canvases.map(canvasRenderer);
  }

  // ---- Drawing.

  // Draw both views from the camera (from the turning mesh when `turning`); returns the
  // milliseconds it took, the GPU's work included.
  function redraw(turning) {
    if (!shown) return 0;
    if (shown.colouredBy !== colourBy.value) recolour();
    var started = performance.now();
    renderers.forEach(function (r, k) { r.draw(cameraView(canvases[k]), turning === true); });
    renderers.forEach(function (r) { r.finish(); });
    var ms = performance.now() - started;
    box.dataset.redrawMs = ms.toFixed(1);
    placePicks();
    return ms;
  }

  // Colours change with the colouring, not with the camera: computed and sent once per choice.
  function recolour() {
    shown.views.forEach(function (view, k) { renderers[k].setColours(faceColours(view)); });
    shown.colouredBy = colourBy.value;
    notePicks();
  }

  // Redraw, then describe the pictures for the browser tests.
  function show() {
    redraw();
    describe();
  }

  // The non-background pixels of the smaller view, a checksum of both pictures and the left
  // view's centre pixel (the rest mesh's centre, when it shows the rest). Read in the same task
  // as the drawing: WebGL keeps its picture only until the page is composited.
  function describe() {
    if (!shown) return;
    var images = renderers.map(function (r) { return r.image(); }), hash = 2166136261;
    box.dataset.pixels = drawnPixels(images);
    images.forEach(function (pixels) {
      for (var i = 0; i < pixels.length; i++) hash = Math.imul(hash ^ pixels[i], 16777619);
    });
    box.dataset.checksum = (hash >>> 0).toString(16);
    var left = canvases[0], centre = 4 * (left.width * (left.height >> 1) + (left.width >> 1));
    box.dataset.centre = Array.prototype.slice.call(images[0], centre, centre + 3).join(',');
  }

  // The non-background pixels of the smaller of `images` (RGBA, as `image()` gives them).
  function drawnPixels(images) {
    return Math.min.apply(null, images.map(function (pixels) {
      var count = 0;
      for (var i = 0; i < pixels.length; i += 4) {
        if (pixels[i] < 250 || pixels[i + 1] < 250 || pixels[i + 2] < 250) count++;
      }
      return count;
    }));
  }

  // One redraw for the events that came while the last one drew, however many: the redraw runs
  // as the next task (not at an animation frame, which headless Chromium does not always give).
  var nextFrame = null;
  function onNextFrame(f) {
    if (!nextFrame) setTimeout(function () { var g = nextFrame; nextFrame = null; g(); }, 0);
    nextFrame = f;
  }

  // `spin=N` in the address: N redraws, each turning 0.05 rad as a drag does, their median time
  // into data-spin-ms.
  function spin(n) {
    var times = [];
    for (var i = 0; i < n; i++) {
      camera.yaw += 0.05;
      times.push(redraw(true));
    }
    times.sort(function (a, b) { return a - b; });
    if (n > 0) {
      box.dataset.spinMs = times[(n - 1) >> 1].toFixed(1);
      box.dataset.turningPixels = drawnPixels(renderers.map(function (r) { return r.image(); }));
    }
    show();
  }

  // ---- Picking: a click names the vertex under it in both views.

  // The corner of `face` nearest canvas point (x, y).
  function nearestCorner(view, positions, face, x, y) {
    var t = shown.rest.triangles, best = -1, bestDistance = Infinity;
    for (var c = 0; c < 3; c++) {
      var v = t[3 * face + c], p = projectOne(view, positions, v), d = Math.hypot(p[0] - x, p[1] - y);
      if (d < bestDistance) { bestDistance = d; best = v; }
    }
    return best;
  }

  // Clicking (x, y) picks what the pixel there shows: both renderers look at its centre.
  function pickAt(k, x, y) {
    x = Math.floor(x) + 0.5; y = Math.floor(y) + 0.5;
    var view = cameraView(canvases[k]), face = renderers[k].faceAt(view, x, y);
    shown.picked = face < 0 ? null : nearestCorner(view, shown.views[k].positions, face, x, y);
    box.dataset.picked = shown.picked === null ? '' : shown.picked;
    notePicks();
    placePicks();
  }

  // The faces with vertex v as a corner: one pass over the triangles, on a click only.
  function facesAround(t, v) {
    var out = [];
    for (var k = 0; k < t.length; k++) if (t[k] === v) out.push((k / 3) | 0);
    return out;
  }

  // What the label says of vertex v in a view: its role, or the error of the faces around it
  // (the mean of their angle errors, or their area over their rest area).
  function vertexNote(view, v) {
    var rest = shown.rest, mode = colourBy.value, role = ['free', 'fixed', 'handle'][rest.roles[v]];
    if (mode === 'shaded' || view.isRest) return 'vertex ' + v + ': ' + (role || 'role ' + rest.roles[v]);
    if (!view.errors) view.errors = faceErrors(view.positions);
    var faces = facesAround(rest.triangles, v), before = restGeometry(rest).areas, sum = 0, area = 0, area0 = 0;
    faces.forEach(function (f) { sum += view.errors.angle[f]; area += view.errors.areas[f]; area0 += before[f]; });
    var count = ' (' + faces.length + ' faces)';
    if (mode === 'angle') return 'vertex ' + v + ': angle error ' + (sum / faces.length).toFixed(2) + '\u00b0' + count;
    return 'vertex ' + v + ': area \u00d7' + (area / area0).toFixed(3) + count;
  }

  function notePicks() {
    pickLabels.forEach(function (label, k) {
      if (!label) return;
      label.hidden = !shown || shown.picked === null || shown.picked === undefined;
      if (!label.hidden) label.textContent = vertexNote(shown.views[k], shown.picked);
    });
  }

  // Keep each label on its vertex as the camera moves (the canvas may be shown scaled down).
  function placePicks() {
    pickLabels.forEach(function (label, k) {
      if (!label || label.hidden) return;
      var canvas = canvases[k], p = projectOne(cameraView(canvas), shown.views[k].positions, shown.picked);
      var inside = p[0] >= 0 && p[0] < canvas.width && p[1] >= 0 && p[1] < canvas.height;
      label.style.visibility = inside ? '' : 'hidden';
      label.style.left = (canvas.offsetLeft + canvas.clientLeft + p[0] * canvas.clientWidth / canvas.width) + 'px';
      label.style.top = (canvas.offsetTop + canvas.clientTop + p[1] * canvas.clientHeight / canvas.height) + 'px';
    });
  }

  // ---- Opening a case.

  // Show `views` (left, right) of meshes on `rest`'s triangles: the renderers (made the first
  // time) get their meshes, the panes their names; the picked vertex is forgotten.
  function present(rest, views) {
    if (!renderers) {
      renderers = makeRenderers(params.get('renderer') !== 'canvas');
      box.dataset.renderer = renderers[0].kind;
    }
    shown = { rest: rest, views: views, reach: reachOf(rest.center, views.map(function (v) { return v.positions; })),
      colouredBy: null, picked: null };
    var turning = turningMesh(rest);
    box.dataset.turningFaces = turning ? turning.faces.length : rest.triangles.length / 3;
    renderers.forEach(function (r, k) { r.setMesh(views[k], rest.triangles, turning); });
    views.forEach(function (v, k) { if (names[k]) names[k].textContent = v.method; });
    delete box.dataset.picked;
    notePicks();
  }

  // Open the view of the row `row` (a results-table row with data-view); `then` runs after its
  // first picture.
  function open(row, leftMethod, then) {
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
          var rest = restMesh(restName);
          present(rest, [left ? viewOf(left.dataset.view, left.dataset.method, false) : viewOf(restName, 'rest', true),
            viewOf(row.dataset.view, row.dataset.method, false)]);
          if (box.dataset.rest !== restName) camera = { yaw: 0.6, pitch: rest.pitch, zoom: 1 };
          box.dataset.rest = restName;
          title.textContent = scenario + ': ' + row.dataset.method;
          redraw();
          box.dataset.loadMs = Math.round(performance.now() - started);
          describe();
          box.dataset.view = row.dataset.view;
          box.dataset.left = left ? left.dataset.method : 'rest';
          if (then) then();
        };
        if (left) load(left.dataset.view, finish); else finish();
      });
    });
  }

  // ---- Controls.

  document.querySelectorAll('#results-table tbody tr[data-view]').forEach(function (row) {
    row.classList.add('viewable');
    row.addEventListener('click', function () { open(row); box.scrollIntoView(); });
  });
  leftChoice.addEventListener('change', function () {
    var current = document.querySelector('#results-table tbody tr[data-view="' + box.dataset.view + '"]');
    var other = document.querySelector('#results-table tbody tr[data-view="' + leftChoice.value + '"]');
    if (current) open(current, other ? other.dataset.method : null);
  });
  colourBy.addEventListener('change', show);
  document.getElementById('viewer-reset').addEventListener('click', function () {
    camera = { yaw: 0.6, pitch: shown ? shown.rest.pitch : -0.35, zoom: 1 }; show();
  });
  document.getElementById('viewer-close').addEventListener('click', function () { box.hidden = true; });

  // The pointer position in canvas pixels (the canvas may be shown scaled down).
  function canvasPoint(canvas, e) {
    var r = canvas.getBoundingClientRect();
    return [(e.clientX - r.left - canvas.clientLeft) * canvas.width / canvas.clientWidth,
      (e.clientY - r.top - canvas.clientTop) * canvas.height / canvas.clientHeight];
  }

  // One camera for both canvases: a drag turns, the wheel zooms, a click without a drag picks.
  // Heard on the canvases' panes: the 2D fallback puts fresh canvases in place.
  var drag = null;
  canvases.forEach(function (canvas, k) {
    var pane = canvas.parentNode;
    pane.addEventListener('mousedown', function (e) {
      drag = { view: k, last: [e.clientX, e.clientY], moved: 0, at: canvasPoint(canvases[k], e) };
      e.preventDefault();
    });
    pane.addEventListener('mousemove', function (e) {
      if (!drag || !shown) return;
      var dx = e.clientX - drag.last[0], dy = e.clientY - drag.last[1];
      drag.moved += Math.abs(dx) + Math.abs(dy);
      camera.yaw += 0.01 * dx;
      camera.pitch = Math.max(-1.5, Math.min(1.5, camera.pitch + 0.01 * dy));
      drag.last = [e.clientX, e.clientY];
      onNextFrame(function () { redraw(true); });
    });
    pane.addEventListener('wheel', function (e) {
      e.preventDefault();
      camera.zoom *= e.deltaY < 0 ? 1.15 : 1 / 1.15;
      onNextFrame(show);
    }, { passive: false });
  });
  window.addEventListener('mouseup', function () {
    var was = drag;
    drag = null;
    if (!was || !shown) return;
    if (was.moved < 3) pickAt(was.view, was.at[0], was.at[1]); else onNextFrame(show);
  });

  // ---- The address: `colour`, `view`, `left`, and for tests and measuring `yaw`, `pick`, `spin`.

  if (params.get('colour')) colourBy.value = params.get('colour');
  var asked = params.get('view') &&
    document.querySelector('#results-table tbody tr[data-view="' + CSS.escape(params.get('view')) + '"]');
  if (asked) {
    open(asked, params.get('left'), function () {
      if (params.get('yaw') !== null) { camera.yaw = parseFloat(params.get('yaw')) || 0; show(); }
      var at = (params.get('pick') || '').split(',').map(parseFloat);
      if (at.length === 2 && !isNaN(at[0]) && !isNaN(at[1])) pickAt(1, at[0], at[1]);
      if (params.get('spin')) spin(parseInt(params.get('spin'), 10) || 0);
    });
  }
})();
