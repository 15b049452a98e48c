// rigidfem's 3D viewer: plays the poses that rigidfem.view wrote into window.RIGIDFEM (no network).
// Bodies are boxes of their equivalent inertia and triads, beams tubes through their rfes' origins
// and tips, force elements and loop joints lines and markers, trails the paths of chosen points.
(function () {
  "use strict";
  const D = window.RIGIDFEM;
  const status = document.body.dataset;
  // what the page logs as an error is recorded where a test (or a teacher's console) sees it
  window.addEventListener("error", (e) => { status.error = String(e.message || e); });
  window.addEventListener("unhandledrejection", (e) => { status.error = String(e.reason); });
  const consoleError = console.error.bind(console);
  console.error = (...args) => { status.error = args.map(String).join(" "); consoleError(...args); };

  // poses: frames x bodies x 12 (R row by row, then the origin), little-endian float32
  const raw = atob(D.poses);
  const bytes = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; ++i) bytes[i] = raw.charCodeAt(i);
  const poses = new Float32Array(bytes.buffer);
  const nb = D.bodies.length, nf = D.t.length;

  // x_global = R r + p of the point r (body frame) of body b at frame k; b = -1: the ground
  function point(k, b, r, out) {
    if (b < 0) return out.set(r[0], r[1], r[2]);
    const o = (k * nb + b) * 12, P = poses;
    return out.set(P[o] * r[0] + P[o + 1] * r[1] + P[o + 2] * r[2] + P[o + 9],
                   P[o + 3] * r[0] + P[o + 4] * r[1] + P[o + 5] * r[2] + P[o + 10],
                   P[o + 6] * r[0] + P[o + 7] * r[1] + P[o + 8] * r[2] + P[o + 11]);
  }
  function matrix(k, b, m) {
    const o = (k * nb + b) * 12, P = poses;
    m.set(P[o], P[o + 1], P[o + 2], P[o + 9], P[o + 3], P[o + 4], P[o + 5], P[o + 10],
          P[o + 6], P[o + 7], P[o + 8], P[o + 11], 0, 0, 0, 1);
    return m;
  }

  const view = document.getElementById("rf-view");
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xffffff, 1);
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const L = D.size;
  const camera = new THREE.PerspectiveCamera(40, 1, 1e-3 * L, 100 * L);
  const c = new THREE.Vector3(...D.centre);
  camera.up.set(...D.up);
  camera.position.set(c.x + 0.5 * L, c.y - 0.7 * L, c.z + 0.3 * L).addScaledVector(new THREE.Vector3(...D.up), 0.3 * L);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(c);
  controls.update();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x666666, 0.9));
  const sun = new THREE.DirectionalLight(0xffffff, 0.6);
  sun.position.set(L, -L, 2 * L);
  scene.add(sun);
  scene.add(new THREE.AxesHelper(0.15 * L));

  // bodies: a box of the equivalent uniform inertia about the centre of mass, and a triad
  const bodyObjects = D.bodies.map((b, i) => {
    const g = new THREE.Group();
    g.matrixAutoUpdate = false;
    if (b.box) {
      const mesh = new THREE.Mesh(new THREE.BoxGeometry(...b.box),
                                  new THREE.MeshLambertMaterial({ color: b.base ? 0x8899aa : 0x4f7fbf }));
      mesh.position.set(...b.com);
      g.add(mesh);
    }
    if (b.triad > 0) { const a = new THREE.AxesHelper(b.triad); g.add(a); }
    scene.add(g);
    return g;
  });

  // shapes of the contacts, fixed in their bodies' frames (the ground's in the scene): translucent, a half-space as a
  // square of the scene's size on its plane
  const shapeMaterial = new THREE.MeshLambertMaterial({ color: 0x4f9e5a, transparent: true, opacity: 0.8 });
  const planeMaterial = new THREE.MeshLambertMaterial({ color: 0xb8b8b0, transparent: true, opacity: 0.5,
                                                        side: THREE.DoubleSide });
  const yAxis = new THREE.Vector3(0, 1, 0), zAxis = new THREE.Vector3(0, 0, 1);
  (D.shapes || []).forEach((s) => {
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
      shape.position.set(...s.a);
      shape.quaternion.setFromUnitVectors(zAxis, new THREE.Vector3(...s.normal));
    }
    (s.body >= 0 ? bodyObjects[s.body] : scene).add(shape);
  });

  // beams: a tube through the rfes' origins and the tip, rebuilt at each frame
  const beamMaterial = new THREE.MeshLambertMaterial({ color: 0xd08030 });
  const beams = D.beams.map((beam) => {
    const mesh = new THREE.Mesh(new THREE.BufferGeometry(), beamMaterial);
    scene.add(mesh);
    return { beam, mesh, pts: beam.bodies.map(() => new THREE.Vector3()).concat([new THREE.Vector3()]) };
  });

  // force elements and loop joints: lines between their two points; joints also a marker
  const colours = { spring: 0x228833, cylinder: 0x6644aa, rope: 0x222222, actuator: 0xaa3377, loop: 0xcc2222 };
  const segments = D.segments.map((s) => {
    const geo = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]);
    const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: colours[s.kind] || 0x000000 }));
    scene.add(line);
    let marker = null;
    if (s.kind === "loop") {
      marker = new THREE.Mesh(new THREE.SphereGeometry(0.015 * L, 12, 8),
                              new THREE.MeshLambertMaterial({ color: colours.loop }));
      scene.add(marker);
    }
    return { s, line, marker };
  });

  // trails: the path of a point from the start up to the current frame
  const trails = D.trails.map((tr) => {
    const pts = new Float32Array(3 * nf), v = new THREE.Vector3();
    for (let k = 0; k < nf; ++k) { point(k, tr.body, tr.r, v); pts.set([v.x, v.y, v.z], 3 * k); }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.BufferAttribute(pts, 3));
    const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: 0xe03c31 }));
    scene.add(line);
    return { geo };
  });

  const tmp = new THREE.Vector3(), tmp2 = new THREE.Vector3(), M = new THREE.Matrix4();
  let frame = 0;
  function show(k) {
    frame = Math.max(0, Math.min(nf - 1, k | 0));
    bodyObjects.forEach((g, i) => { g.matrix.copy(matrix(frame, i, M)); g.matrixWorldNeedsUpdate = true; });
    beams.forEach((b) => {
      b.beam.bodies.forEach((body, j) => point(frame, body, [0, 0, 0], b.pts[j]));
      const tip = b.beam.tips ? b.beam.tips[frame] : b.beam.tip;  // a link of varying length: L(t)
      point(frame, b.beam.bodies[b.beam.bodies.length - 1], tip, b.pts[b.pts.length - 1]);
      const curve = new THREE.CatmullRomCurve3(b.pts);
      b.mesh.geometry.dispose();
      b.mesh.geometry = new THREE.TubeGeometry(curve, 4 * b.pts.length, b.beam.radius, 8, false);
    });
    segments.forEach((g) => {
      point(frame, g.s.a[0], g.s.a[1], tmp);
      point(frame, g.s.b[0], g.s.b[1], tmp2);
      const p = g.line.geometry.attributes.position;
      p.setXYZ(0, tmp.x, tmp.y, tmp.z); p.setXYZ(1, tmp2.x, tmp2.y, tmp2.z); p.needsUpdate = true;
      if (g.marker) g.marker.position.copy(tmp);
    });
    trails.forEach((tr) => tr.geo.setDrawRange(0, frame + 1));
    slider.value = frame;
    clock.textContent = "t = " + D.t[frame].toFixed(3) + " s";
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
    render();
  }
  controls.addEventListener("change", render);
  window.addEventListener("resize", resize);

  // controls: play/pause, the time slider, the playback speed (simulated s per real s), the time
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
    simTime += (now - last) / 1000 * (+speed.value);
    last = now;
    let k = frame;
    while (k < nf - 1 && D.t[k + 1] <= simTime) ++k;
    show(k);
    if (k >= nf - 1) { playing = false; play.textContent = "play"; return; }
    requestAnimationFrame(tick);
  }

  // the pixels of the picture: how many differ from the background, and a hash of them (tests)
  window.rigidfemProbe = function () {
    const cv = document.createElement("canvas");
    cv.width = renderer.domElement.width; cv.height = renderer.domElement.height;
    const ctx = cv.getContext("2d");
    ctx.drawImage(renderer.domElement, 0, 0);
    const px = ctx.getImageData(0, 0, cv.width, cv.height).data;
    let ink = 0, hash = 2166136261;
    for (let i = 0; i < px.length; i += 4) {
      if (px[i] < 250 || px[i + 1] < 250 || px[i + 2] < 250) ++ink;
      hash = Math.imul(hash ^ (px[i] + 3 * px[i + 1] + 7 * px[i + 2]), 16777619) >>> 0;
    }
    status.ink = ink; status.hash = hash; status.pixels = px.length / 4;
    return { ink, hash };
  };

  // the page around (the notebook widget) picks the frame: {rigidfem: "frame", frame: K}
  window.addEventListener("message", (e) => {
    if (e.data && e.data.rigidfem === "frame" && +e.data.frame !== frame) {
      playing = false; play.textContent = "play"; show(+e.data.frame);
    }
  });

  // #frame=K or #t=T picks the frame shown first (links, tests); #probe=1 records the pixels
  const hash = new URLSearchParams(window.location.hash.slice(1));
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
  if (hash.get("bench") === "1") {  // every frame shown once, as playing does: ms per frame
    const t0 = performance.now();
    for (let k = 0; k < nf; ++k) show(k);
    renderer.getContext().finish();
    status.msPerFrame = ((performance.now() - t0) / nf).toFixed(2);
  }
  status.ready = "1";
})();
