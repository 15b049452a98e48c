// rigidfem's 3D viewer: plays the poses that rigidfem.view wrote into window.RIGIDFEM (no network).
// Bodies are boxes of their equivalent inertia and triads (a URDF robot's by its links' visual geometry),
// beams tubes through their rfes' origins
// and tips (coloured by an sde quantity when one is given), force elements and loop joints lines and
// markers (ropes coloured by their tension), trails the paths of chosen points, force arrows; a ground
// grid whose square the legend names. Several layers (results or modes) each have their own poses.
(function () {
  "use strict";
  const D = window.RIGIDFEM;
  const status = document.body.dataset;
  // what the page logs as an error is recorded where a test (or a teacher's console) sees it
  window.addEventListener("error", (e) => { status.error = String(e.message || e); });
  window.addEventListener("unhandledrejection", (e) => { status.error = String(e.reason); });
  const consoleError = console.error.bind(console);
  console.error = (...args) => { status.error = args.map(String).join(" "); consoleError(...args); };

  // little-endian float32 (and uint32) arrays written by Python as base64
  function bytes(b64) {
    const raw = atob(b64), out = new Uint8Array(raw.length);
    for (let i = 0; i < raw.length; ++i) out[i] = raw.charCodeAt(i);
    return out.buffer;
  }
  function floats(b64) { return new Float32Array(bytes(b64)); }
  function uints(b64) { return new Uint32Array(bytes(b64)); }
  const hash = new URLSearchParams(window.location.hash.slice(1));
  const helpers = hash.get("helpers") !== "0";  // #helpers=0: the model alone (tests measure its pixels)
  const nf = D.t.length, L = D.scene_size || D.size;

  // the colour map of quantities (viridis, 5 stops) and a value's colour in [lo, hi]
  const MAP = [[0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551], [0.369, 0.789, 0.383],
               [0.993, 0.906, 0.144]];
  function mapColour(v, lo, hi, out) {
    let x = hi > lo ? (v - lo) / (hi - lo) : 0.5;
    x = Math.max(0, Math.min(1, x)) * (MAP.length - 1);
    const i = Math.min(MAP.length - 2, Math.floor(x)), f = x - i, a = MAP[i], b = MAP[i + 1];
    return out.setRGB(a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]));
  }
  const bars = {};
  (D.colour_bars || []).forEach((b) => { bars[b.what] = b; });

  const view = document.getElementById("rf-view");
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xffffff, 1);
  view.insertBefore(renderer.domElement, view.firstChild);
  const scene = new THREE.Scene();

  // the camera: looking along -dir at the scene's box (its extents in the camera's axes right, up', dir),
  // as far as the box needs to fit the picture (the fit is made again when the picture's shape changes)
  const C = D.camera, up = new THREE.Vector3(...C.up), dir = new THREE.Vector3(...C.dir);
  const right = new THREE.Vector3(...C.right), upv = new THREE.Vector3().crossVectors(dir, right);
  const lo = C.extent[0], hi = C.extent[1];
  const target = new THREE.Vector3(...C.centre).addScaledVector(right, 0.5 * (lo[0] + hi[0]))
    .addScaledVector(upv, 0.5 * (lo[1] + hi[1]));
  const camera = new THREE.PerspectiveCamera(40, 1, 1e-3 * D.size, 100 * D.size);
  camera.up.copy(up);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  function fit(aspect) {
    const margin = 0.88, tanV = Math.tan(THREE.Math.degToRad(camera.fov / 2)) * margin, tanH = tanV * aspect;
    const hx = 0.5 * (hi[0] - lo[0]), hy = 0.5 * (hi[1] - lo[1]);
    let dist = 0;
    [lo[2], hi[2]].forEach((z) => { dist = Math.max(dist, z + hx / tanH, z + hy / tanV); });
    dist = Math.max(dist, hi[2] + 0.05 * D.size);
    camera.position.copy(target).addScaledVector(dir, dist);
    camera.near = Math.max(1e-4 * D.size, 0.01 * (dist - hi[2]));
    camera.far = dist + 20 * D.size;
    camera.lookAt(target);
    controls.target.copy(target);
    controls.update();
  }
  scene.add(new THREE.HemisphereLight(0xffffff, 0x666666, 0.9));
  const sun = new THREE.DirectionalLight(0xffffff, 0.6);
  sun.position.copy(dir).addScaledVector(up, 1).addScaledVector(right, 0.5).multiplyScalar(D.size);
  scene.add(sun);

  // the ground grid (its square named in the legend) and the global triad, the helpers
  const helperObjects = [];
  if (D.grid) {
    const G = D.grid, o = new THREE.Vector3(...G.origin), a = new THREE.Vector3(...G.a), b = new THREE.Vector3(...G.b);
    const [a0, a1, b0, b1] = G.range, pts = [], major = [];
    const at = (x, y) => o.clone().addScaledVector(a, x).addScaledVector(b, y);
    const n = (v) => Math.round(v / G.step);
    for (let i = n(a0); i <= n(a1); ++i) (i % 5 ? pts : major).push(at(i * G.step, b0), at(i * G.step, b1));
    for (let j = n(b0); j <= n(b1); ++j) (j % 5 ? pts : major).push(at(a0, j * G.step), at(a1, j * G.step));
    [[pts, 0xdddddd], [major, 0xaaaaaa]].forEach(([p, colour]) => {
      const lines = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(p),
                                           new THREE.LineBasicMaterial({ color: colour }));
      helperObjects.push(lines);
    });
  }
  helperObjects.push(new THREE.AxesHelper(0.1 * L));
  helperObjects.forEach((h) => { h.visible = helpers; scene.add(h); });

  // one layer: a result, a state or a mode, with its own bodies and poses, placed at its offset
  const colours = { spring: 0x228833, cylinder: 0x6644aa, rope: 0x222222, actuator: 0xaa3377, loop: 0xcc2222 };
  const arrowColours = { load: 0xd62728, element: 0x555555, contact: 0x1f77b4 };
  const yAxis = new THREE.Vector3(0, 1, 0), zAxis = new THREE.Vector3(0, 0, 1);
  function makeLayer(Y, k) {
    const poses = floats(Y.poses), nb = Y.bodies.length, off = new THREE.Vector3(...(Y.offset || [0, 0, 0]));
    const palette = Y.palette || [0xd08030, 0x4f7fbf];
    // x_global = R r + p (+ the layer's offset) of the point r (body frame) of body b at frame k; b = -1: the ground
    function point(k, b, r, out) {
      if (b < 0) return out.set(r[0] + off.x, r[1] + off.y, r[2] + off.z);
      const o = (k * nb + b) * 12, P = poses;
      return out.set(P[o] * r[0] + P[o + 1] * r[1] + P[o + 2] * r[2] + P[o + 9] + off.x,
                     P[o + 3] * r[0] + P[o + 4] * r[1] + P[o + 5] * r[2] + P[o + 10] + off.y,
                     P[o + 6] * r[0] + P[o + 7] * r[1] + P[o + 8] * r[2] + P[o + 11] + off.z);
    }
    function matrix(k, b, m) {
      const o = (k * nb + b) * 12, P = poses;
      return m.set(P[o], P[o + 1], P[o + 2], P[o + 9] + off.x, P[o + 3], P[o + 4], P[o + 5], P[o + 10] + off.y,
                   P[o + 6], P[o + 7], P[o + 8], P[o + 11] + off.z, 0, 0, 0, 1);
    }
    // bodies: a box of the equivalent uniform inertia about the centre of mass, and a triad
    const bodyMaterial = new THREE.MeshLambertMaterial({ color: palette[1] });
    const baseMaterial = new THREE.MeshLambertMaterial({ color: 0x8899aa });
    const bodyObjects = Y.bodies.map((b) => {
      const g = new THREE.Group();
      g.matrixAutoUpdate = false;
      if (b.box) {
        const mesh = new THREE.Mesh(new THREE.BoxGeometry(...b.box), b.base ? baseMaterial : bodyMaterial);
        mesh.position.set(...b.com);
        g.add(mesh);
      }
      if (b.triad > 0) g.add(new THREE.AxesHelper(b.triad));
      scene.add(g);
      return g;
    });
    // a URDF robot's visual geometry, fixed in its bodies' frames (the ground's at the layer's offset): meshes
    // (vertices already in the body's frame, shaded flat, both sides lit), boxes, cylinders (along z) and spheres
    // placed by their matrices; the file's colour, or the layer's body colour
    const ground = new THREE.Group();
    ground.position.copy(off);
    scene.add(ground);
    (Y.visuals || []).forEach((v) => {
      const material = new THREE.MeshLambertMaterial({ color: v.colour == null ? palette[1] : v.colour,
                                                       side: THREE.DoubleSide, transparent: v.opacity < 1,
                                                       opacity: v.opacity });
      let geometry;
      if (v.kind === "mesh") {
        const indexed = new THREE.BufferGeometry();
        indexed.setAttribute("position", new THREE.BufferAttribute(floats(v.vertices), 3));
        indexed.setIndex(new THREE.BufferAttribute(uints(v.indices), 1));
        geometry = indexed.toNonIndexed();  // a normal per face: CAD edges stay sharp
        indexed.dispose();
        geometry.computeVertexNormals();
      } else if (v.kind === "box") {
        geometry = new THREE.BoxBufferGeometry(v.size[0], v.size[1], v.size[2]);
      } else if (v.kind === "cylinder") {
        geometry = new THREE.CylinderBufferGeometry(v.size[0], v.size[0], v.size[1], 32).rotateX(Math.PI / 2);
      } else {
        geometry = new THREE.SphereBufferGeometry(v.size[0], 24, 16);
      }
      const mesh = new THREE.Mesh(geometry, material);
      if (v.matrix) {
        mesh.matrixAutoUpdate = false;
        mesh.matrix.set(...v.matrix);
      }
      (v.body >= 0 ? bodyObjects[v.body] : ground).add(mesh);
    });
    // shapes of the contacts, fixed in their bodies' frames (the ground's in the scene): translucent, a
    // half-space as a square of the scene's size on its plane
    const shapeMaterial = new THREE.MeshLambertMaterial({ color: 0x4f9e5a, transparent: true, opacity: 0.8 });
    const planeMaterial = new THREE.MeshLambertMaterial({ color: 0xb8b8b0, transparent: true, opacity: 0.5,
                                                          side: THREE.DoubleSide });
    (Y.shapes || []).forEach((s) => {
      const shape = new THREE.Group();
      if (s.kind === "sphere") {
        shape.add(new THREE.Mesh(new THREE.SphereGeometry(s.radius, 20, 14), shapeMaterial));
        shape.position.set(...s.a);
      } else if (s.kind === "capsule") {  // a cylinder (along y) between two spheres
        const a = new THREE.Vector3(...s.a), b = new THREE.Vector3(...s.b), len = a.distanceTo(b);
        shape.add(new THREE.Mesh(new THREE.CylinderGeometry(s.radius, s.radius, len, 16, 1, true), shapeMaterial));
        [-0.5, 0.5].forEach((y) => {
          const end = new THREE.Mesh(new THREE.SphereGeometry(s.radius, 16, 12), shapeMaterial);
          end.position.set(0, y * len, 0);
          shape.add(end);
        });
        shape.position.copy(a).add(b).multiplyScalar(0.5);
        if (len > 0) shape.quaternion.setFromUnitVectors(yAxis, b.clone().sub(a).normalize());
      } else if (s.kind === "box") {
        const h = s.half_extents, R = s.rotation;
        shape.add(new THREE.Mesh(new THREE.BoxGeometry(2 * h[0], 2 * h[1], 2 * h[2]), shapeMaterial));
        shape.position.set(...s.a);
        shape.quaternion.setFromRotationMatrix(new THREE.Matrix4().set(R[0], R[1], R[2], 0, R[3], R[4], R[5], 0,
                                                                       R[6], R[7], R[8], 0, 0, 0, 0, 1));
      } else if (s.kind === "half_space") {
        const plane = new THREE.Mesh(new THREE.PlaneGeometry(2 * L, 2 * L), planeMaterial);
        shape.add(plane);
        shape.position.set(...s.a).add(off);
        shape.quaternion.setFromUnitVectors(zAxis, new THREE.Vector3(...s.normal));
      }
      (s.body >= 0 ? bodyObjects[s.body] : scene).add(shape);
    });

    // beams: a tube through the rfes' origins and the tip, rebuilt at each frame; with values (an sde quantity
    // at each rfe's joint), coloured along its length, linearly between the sdes
    const beams = Y.beams.map((beam) => {
      const values = beam.values ? floats(beam.values) : null;
      const material = values ? new THREE.MeshLambertMaterial({ color: 0xffffff, vertexColors: THREE.VertexColors })
                              : new THREE.MeshLambertMaterial({ color: palette[0] });
      const mesh = new THREE.Mesh(new THREE.BufferGeometry(), material);
      scene.add(mesh);
      return { beam, mesh, values, pts: beam.bodies.map(() => new THREE.Vector3()).concat([new THREE.Vector3()]) };
    });
    const colour = new THREE.Color();
    function colourTube(b, k, geometry, tubular, radial) {
      const m = b.beam.bodies.length - 1, bar = bars.sdes, s = [0];
      for (let j = 1; j < b.pts.length; ++j) s.push(s[j - 1] + b.pts[j].distanceTo(b.pts[j - 1]));
      const total = s[s.length - 1] || 1, rgb = new Float32Array(3 * (tubular + 1) * (radial + 1));
      let seg = 1;
      for (let i = 0; i <= tubular; ++i) {
        const x = i / tubular * total;  // arc length of the ring (TubeBufferGeometry spaces rings by arc length)
        while (seg < m && s[seg + 1] < x) ++seg;
        let v;
        if (m < 1) v = 0;
        else if (x <= s[1]) v = b.values[k * m];
        else if (seg >= m) v = b.values[k * m + m - 1];
        else {
          const f = (x - s[seg]) / Math.max(s[seg + 1] - s[seg], 1e-30);
          v = (1 - f) * b.values[k * m + seg - 1] + f * b.values[k * m + seg];
        }
        mapColour(v, bar.lo, bar.hi, colour);
        for (let j = 0; j <= radial; ++j) rgb.set([colour.r, colour.g, colour.b], 3 * (i * (radial + 1) + j));
      }
      geometry.setAttribute("color", new THREE.BufferAttribute(rgb, 3));
    }

    // force elements and loop joints: lines between their two points (ropes coloured by their tension); joints
    // also a marker
    const segments = Y.segments.map((s) => {
      const geo = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]);
      const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: colours[s.kind] || 0x000000 }));
      scene.add(line);
      let marker = null;
      if (s.kind === "loop") {
        marker = new THREE.Mesh(new THREE.SphereGeometry(0.015 * L, 12, 8),
                                new THREE.MeshLambertMaterial({ color: colours.loop }));
        scene.add(marker);
      }
      return { s, line, marker, values: s.values ? floats(s.values) : null };
    });

    // trails: the path of a point from the start up to the current frame
    const trails = D.trails.map((tr) => {
      const pts = new Float32Array(3 * nf), v = new THREE.Vector3();
      for (let j = 0; j < nf; ++j) { point(j, tr.body, tr.r, v); pts.set([v.x, v.y, v.z], 3 * j); }
      const geo = new THREE.BufferGeometry();
      geo.setAttribute("position", new THREE.BufferAttribute(pts, 3));
      scene.add(new THREE.Line(geo, new THREE.LineBasicMaterial({ color: k ? palette[0] : 0xe03c31 })));
      return { geo };
    });

    // force arrows: at a body's point (or a contact's point), along the force, D.arrows.scale m per N
    const arrows = (Y.arrows || []).map((a) => {
      const helper = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 1,
                                           arrowColours[a.kind] || 0x000000);
      scene.add(helper);
      return { a, helper, vectors: floats(a.vectors), points: a.points ? floats(a.points) : null };
    });

    const tmp = new THREE.Vector3(), tmp2 = new THREE.Vector3(), M = new THREE.Matrix4();
    function show(k) {
      bodyObjects.forEach((g, i) => { g.matrix.copy(matrix(k, i, M)); g.matrixWorldNeedsUpdate = true; });
      beams.forEach((b) => {
        b.beam.bodies.forEach((body, j) => point(k, body, [0, 0, 0], b.pts[j]));
        const tip = b.beam.tips ? b.beam.tips[k] : b.beam.tip;  // a link of varying length: L(t)
        point(k, b.beam.bodies[b.beam.bodies.length - 1], tip, b.pts[b.pts.length - 1]);
        const curve = new THREE.CatmullRomCurve3(b.pts), tubular = 4 * b.pts.length, radial = 8;
        b.mesh.geometry.dispose();
        b.mesh.geometry = new THREE.TubeBufferGeometry(curve, tubular, b.beam.radius, radial, false);
        if (b.values) colourTube(b, k, b.mesh.geometry, tubular, radial);
      });
      segments.forEach((g) => {
        point(k, g.s.a[0], g.s.a[1], tmp);
        point(k, g.s.b[0], g.s.b[1], tmp2);
        const p = g.line.geometry.attributes.position;
        p.setXYZ(0, tmp.x, tmp.y, tmp.z); p.setXYZ(1, tmp2.x, tmp2.y, tmp2.z); p.needsUpdate = true;
        if (g.marker) g.marker.position.copy(tmp);
        if (g.values && bars.ropes) mapColour(g.values[k], bars.ropes.lo, bars.ropes.hi, g.line.material.color);
      });
      trails.forEach((tr) => tr.geo.setDrawRange(0, k + 1));
      arrows.forEach((ar) => {
        const v = tmp2.set(ar.vectors[3 * k], ar.vectors[3 * k + 1], ar.vectors[3 * k + 2]);
        const len = v.length() * D.arrow_scale.m_per_N;
        if (ar.points) tmp.set(ar.points[3 * k], ar.points[3 * k + 1], ar.points[3 * k + 2]).add(off);
        else point(k, ar.a.body, ar.a.r, tmp);
        ar.helper.visible = len > 1e-9 * L;
        if (!ar.helper.visible) return;
        ar.helper.position.copy(tmp);
        ar.helper.setDirection(v.normalize());
        ar.helper.setLength(len, Math.min(0.25 * len, 0.04 * L), Math.min(0.12 * len, 0.02 * L));
      });
    }
    return { show };
  }
  const layers = [D].concat(D.layers || []).map(makeLayer);

  // the legend: the layers, the grid's square, the deformation scale, the colour bars, the arrows' scale
  function length(x) {
    if (x >= 1) return +x.toPrecision(3) + " m";
    if (x >= 0.01) return +(x * 100).toPrecision(3) + " cm";
    return +(x * 1000).toPrecision(3) + " mm";
  }
  function number(x) { return Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-2 && x !== 0) ? x.toExponential(2) : +x.toPrecision(3); }
  const legend = document.getElementById("rf-legend"), hex = (c) => "#" + c.toString(16).padStart(6, "0");
  const lines = [];
  (D.legend || []).forEach((l) => lines.push(`<span class="chip" style="background:${hex(l.colour)}"></span>${l.label}`));
  if (D.grid) lines.push(`grid square ${length(D.grid.step)}`);
  if (D.scale !== 1) lines.push(`deformation ×${number(D.scale)}`);
  const gradient = "linear-gradient(to right," + MAP.map((c) => `rgb(${c.map((x) => Math.round(255 * x)).join(",")})`).join(",") + ")";
  (D.colour_bars || []).forEach((b) => lines.push(`${b.label} ${number(b.lo)}<span class="bar" style="background:${gradient}"></span>${number(b.hi)}`));
  if (D.arrow_scale) lines.push(`arrows: ${length(0.15 * L)} = ${number(D.arrow_scale.largest)} N`);
  legend.innerHTML = lines.join("<br>");
  legend.style.display = lines.length && helpers ? "" : "none";

  let frame = 0;
  function show(k) {
    frame = Math.max(0, Math.min(nf - 1, k | 0));
    layers.forEach((l) => l.show(frame));
    slider.value = frame;
    clock.textContent = D.clock === "phase" ? "phase " + D.t[frame].toFixed(3) + " T" : "t = " + D.t[frame].toFixed(3) + " s";
    status.frame = frame;
    status.time = D.t[frame].toFixed(6);
    render();
    // in an iframe (the notebook widget): tell the page around which frame is shown
    if (window.parent !== window) window.parent.postMessage({ rigidfem: "shown", frame }, "*");
  }

  function render() { renderer.render(scene, camera); status.rendered = (+status.rendered || 0) + 1; }
  function resize() {
    const w = view.clientWidth || 640, h = view.clientHeight || 420;
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    fit(w / h);
    camera.updateProjectionMatrix();
    render();
  }
  controls.addEventListener("change", render);
  window.addEventListener("resize", resize);

  // controls: play/pause, the time slider, the playback speed (simulated s per real s), the time, the snapshot
  const slider = document.getElementById("rf-slider"), clock = document.getElementById("rf-time");
  const play = document.getElementById("rf-play"), speed = document.getElementById("rf-speed");
  slider.max = nf - 1;
  slider.addEventListener("input", () => { playing = false; play.textContent = "play"; show(+slider.value); });
  let playing = false, simTime = 0, last = 0;
  play.addEventListener("click", () => {
    playing = !playing;
    play.textContent = playing ? "pause" : "play";
    if (playing) { if (frame >= nf - 1) frame = 0; simTime = D.t[frame]; last = performance.now(); requestAnimationFrame(tick); }
  });
  function tick(now) {
    if (!playing) return;
    simTime += (now - last) / 1000 * (+speed.value) * (D.rate || 1);
    last = now;
    if (D.loop && nf > 1) {  // a mode's period, again and again
      const period = D.t[nf - 1] + (D.t[1] - D.t[0]);
      simTime %= period;
      let k = 0;
      while (k < nf - 1 && D.t[k + 1] <= simTime) ++k;
      show(k);
      requestAnimationFrame(tick);
      return;
    }
    let k = frame;
    while (k < nf - 1 && D.t[k + 1] <= simTime) ++k;
    show(k);
    if (k >= nf - 1) { playing = false; play.textContent = "play"; return; }
    requestAnimationFrame(tick);
  }
  // the snapshot: the picture as a PNG file (the canvas keeps its drawing buffer)
  function snapshot() { render(); return renderer.domElement.toDataURL("image/png"); }
  window.rigidfemSnapshot = snapshot;
  document.getElementById("rf-snapshot").addEventListener("click", () => {
    const a = document.createElement("a");
    a.href = snapshot();
    a.download = (D.title || "rigidfem").replace(/[^\w.-]+/g, "_") + "_" + frame + ".png";
    status.snapshots = (+status.snapshots || 0) + 1;
    status.snapshot = a.download + " " + a.href.slice(0, 22);
    if (hash.get("download") === "0") return;  // #download=0: the file prepared, not saved (tests)
    document.body.appendChild(a);
    a.click();
    a.remove();
  });

  // the pixels of the picture: how many differ from the background, and a hash of them (tests)
  window.rigidfemProbe = function () {
    const cv = document.createElement("canvas");
    cv.width = renderer.domElement.width; cv.height = renderer.domElement.height;
    const ctx = cv.getContext("2d");
    ctx.drawImage(renderer.domElement, 0, 0);
    const px = ctx.getImageData(0, 0, cv.width, cv.height).data;
    let ink = 0, h = 2166136261;
    for (let i = 0; i < px.length; i += 4) {
      if (px[i] < 250 || px[i + 1] < 250 || px[i + 2] < 250) ++ink;
      h = Math.imul(h ^ (px[i] + 3 * px[i + 1] + 7 * px[i + 2]), 16777619) >>> 0;
    }
    status.ink = ink; status.hash = h; status.pixels = px.length / 4;
    return { ink, hash: h };
  };

  // the page around (the notebook widget) picks the frame: {rigidfem: "frame", frame: K}
  window.addEventListener("message", (e) => {
    if (e.data && e.data.rigidfem === "frame" && +e.data.frame !== frame) {
      playing = false; play.textContent = "play"; show(+e.data.frame);
    }
  });

  // #frame=K or #t=T picks the frame shown first (links, tests); #probe=1 records the pixels; #shots=0,10,-1
  // records the snapshots of those frames (-1: the last) in data-shot0, data-shot1, ...; #click=snapshot presses
  // the snapshot button
  resize();
  let first = 0;
  if (hash.has("frame")) first = +hash.get("frame");
  if (hash.has("t")) { const t = +hash.get("t"); while (first < nf - 1 && D.t[first + 1] <= t) ++first; }
  show(first);
  if (hash.has("slide")) {  // as a hand would: the slider moved, its input event handled
    slider.value = +hash.get("slide");
    slider.dispatchEvent(new Event("input"));
  }
  if (hash.get("probe") === "1") window.rigidfemProbe();
  if (hash.has("shots")) {
    hash.get("shots").split(",").forEach((s, i) => {
      show(+s < 0 ? nf + +s : +s);
      status["shot" + i] = snapshot();
    });
  }
  if (hash.get("click") === "snapshot") document.getElementById("rf-snapshot").click();
  if (hash.get("bench") === "1") {  // every frame shown once, as playing does: ms per frame
    const t0 = performance.now();
    for (let k = 0; k < nf; ++k) show(k);
    renderer.getContext().finish();
    status.msPerFrame = ((performance.now() - t0) / nf).toFixed(2);
  }
  status.ready = "1";
})();
