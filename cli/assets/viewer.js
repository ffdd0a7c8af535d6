// The lagrange viewer (`lagrange view`, `simulate --view`, `view --live`): draws the scene and
// frames that cli/src/cli/view/scene.rs writes into the page with three.js (the bundle inlined
// before this script defines the global THREE). Nothing is loaded from the network; the live mode
// reads server-sent events from the page's own server (a relative URL).
// The page's state is window.lagrangeViewer (the browser tests in cli/tests/viewer_browser.rs
// read it).
(function () {
  'use strict';
  const errors = [];
  window.addEventListener('error', (e) => errors.push(String(e.message)));
  const readJson = (id) => JSON.parse(document.getElementById(id).textContent);
  const S = readJson('lagrange-scene');
  const config = readJson('lagrange-config');
  const POSE = 7, CONTACT = 6;

  function b64(s, Type) {
    const bin = atob(s);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }

  // Frames: time, poses (nslot × 7), qpos (nq), contacts (k × 6) per frame.
  const frames = [];
  function addFrame(time, poses, qpos, contacts) {
    frames.push({ time, poses, qpos, contacts });
  }
  {
    const F = readJson('lagrange-frames');
    const poses = b64(F.poses, Float32Array), qpos = b64(F.qpos, Float32Array);
    const contacts = b64(F.contacts, Float32Array);
    const np = S.nslot * POSE;
    for (let k = 0; k < F.n; k++) {
      addFrame(F.time[k], poses.subarray(k * np, (k + 1) * np), qpos.subarray(k * S.nq, (k + 1) * S.nq),
        contacts.subarray(F.contact_start[k] * CONTACT, F.contact_start[k + 1] * CONTACT));
    }
  }

  // Renderer, camera (z up, as the models), lights.
  const view = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const background = new THREE.Color(0.78, 0.84, 0.9);
  scene.background = background;
  const camera = new THREE.PerspectiveCamera(45, 1, 0.005, 2000);
  camera.up.set(0, 0, 1);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 2.0);
  scene.add(sun);

  // One group per pose slot (compiled bodies, then mocap bodies); the world's stays put.
  const slots = [];
  for (let s = 0; s < S.nslot; s++) {
    const g = new THREE.Group();
    g.matrixAutoUpdate = true;
    scene.add(g);
    slots.push(g);
  }

  const meshGeometries = S.meshes.map((m) => {
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(b64(m.vertices, Float32Array), 3));
    geo.setIndex(new THREE.BufferAttribute(b64(m.indices, Uint32Array), 1));
    geo.computeVertexNormals();
    return geo;
  });

  function geometryOf(g) {
    const s = g.size;
    switch (g.type) {
      case 'box': return new THREE.BoxGeometry(s[0], s[1], s[2]);
      case 'sphere': return new THREE.SphereGeometry(s[0], 32, 16);
      case 'ellipsoid': { const geo = new THREE.SphereGeometry(1, 32, 16); geo.scale(s[0], s[1], s[2]); return geo; }
      case 'capsule': { const geo = new THREE.CapsuleGeometry(s[0], s[1], 8, 24); geo.rotateX(Math.PI / 2); return geo; }
      case 'cylinder': { const geo = new THREE.CylinderGeometry(s[0], s[0], s[1], 32); geo.rotateX(Math.PI / 2); return geo; }
      case 'mesh': return meshGeometries[g.mesh];
      default: return null;
    }
  }

  const robotMeshes = [], hiddenByDefault = [], floors = [];
  const planes = [];
  for (const g of S.geoms) {
    const [r, gr, b, a] = g.rgba;
    if (a <= 0) continue;
    const color = new THREE.Color().setRGB(r, gr, b, THREE.SRGBColorSpace);
    const material = new THREE.MeshStandardMaterial({
      color, roughness: 0.75, metalness: 0.05, transparent: a < 1, opacity: a,
      side: g.type === 'mesh' || g.type === 'plane' ? THREE.DoubleSide : THREE.FrontSide,
    });
    // Floors are drawn 30 % darker than their rgba: MuJoCo's default grey is also the default
    // of the bodies standing on them.
    if (g.type === 'plane') { material.color.multiplyScalar(0.7); planes.push({ g, material }); continue; }
    const geo = geometryOf(g);
    if (!geo) continue;
    const mesh = new THREE.Mesh(geo, material);
    mesh.position.fromArray(g.pos);
    mesh.quaternion.fromArray(g.quat);
    mesh.name = g.name;
    mesh.visible = g.visible;
    if (!g.visible) hiddenByDefault.push(mesh);
    slots[g.slot].add(mesh);
    if (!g.world) robotMeshes.push(mesh);
  }

  // Frames of links and sites, shown on demand.
  const linkAxes = [], siteMarks = [];
  function addFrameMarks(size) {
    for (const f of S.frames) {
      const o = new THREE.Group();
      o.position.fromArray(f.pos);
      o.quaternion.fromArray(f.quat);
      const axes = new THREE.AxesHelper(f.kind === 'site' ? size * 0.5 : size);
      o.add(axes);
      if (f.kind === 'site') {
        o.add(new THREE.Mesh(new THREE.SphereGeometry(size * 0.08, 12, 8),
          new THREE.MeshStandardMaterial({ color: 0xd03030 })));
        siteMarks.push(o);
      } else {
        linkAxes.push(o);
      }
      o.visible = false;
      slots[f.slot].add(o);
    }
  }

  function applyFrame(k) {
    const f = frames[k];
    if (!f) return;
    for (let s = 0; s < S.nslot; s++) {
      const p = f.poses.subarray(s * POSE, s * POSE + POSE);
      slots[s].position.set(p[0], p[1], p[2]);
      slots[s].quaternion.set(p[3], p[4], p[5], p[6]);
    }
    scene.updateMatrixWorld(true);
  }

  // The robot's box over the frames (at most 200 of them sampled) frames the camera.
  const box = new THREE.Box3();
  const sampled = Math.max(1, Math.ceil(frames.length / 200));
  for (let k = 0; k < Math.max(frames.length, 1); k += sampled) {
    if (frames.length) applyFrame(k);
    for (const m of robotMeshes) if (m.visible) box.expandByObject(m);
  }
  if (frames.length > 1) applyFrame(frames.length - 1);
  for (const m of robotMeshes) if (m.visible) box.expandByObject(m);
  if (box.isEmpty()) for (const m of robotMeshes) box.expandByObject(m);
  if (frames.length) applyFrame(0);
  if (box.isEmpty()) box.set(new THREE.Vector3(-0.5, -0.5, 0), new THREE.Vector3(0.5, 0.5, 1));
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 0.05);
  const dir = new THREE.Vector3(1.0, -1.6, 0.9).normalize();
  const distance = radius / Math.sin((camera.fov * Math.PI) / 360) * 1.15;
  camera.position.copy(center).addScaledVector(dir, distance);
  camera.near = distance / 500;
  camera.far = distance * 200;
  sun.position.copy(center).add(new THREE.Vector3(1, -1, 2.5).multiplyScalar(radius * 4));
  sun.target.position.copy(center);
  scene.add(sun.target);
  addFrameMarks(radius * 0.25);

  for (const { g, material } of planes) {
    // MuJoCo's size 0 means an infinite plane: drawn 8 radii (at least 10 m) wide.
    const ext = Math.max(10, radius * 8);
    const w = g.size[0] > 0 ? 2 * g.size[0] : ext, h = g.size[1] > 0 ? 2 * g.size[1] : ext;
    const mesh = new THREE.Mesh(new THREE.PlaneGeometry(w, h), material);
    mesh.position.fromArray(g.pos);
    mesh.quaternion.fromArray(g.quat);
    mesh.name = g.name;
    const grid = new THREE.GridHelper(Math.max(w, h), Math.round(Math.max(w, h) / Math.max(0.1, gridStep(radius))), 0x666666, 0x999999);
    grid.rotateX(Math.PI / 2);
    grid.position.z = 0.0005 * radius;
    mesh.add(grid);
    mesh.visible = g.visible;
    if (!g.visible) hiddenByDefault.push(mesh);
    slots[g.slot].add(mesh);
    floors.push(mesh);
  }
  function gridStep(r) { return r > 2 ? 1 : r > 0.5 ? 0.25 : 0.1; }

  const { OrbitControls } = THREE;
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(center);
  controls.update();

  // Contact points and force arrows, a pool grown as needed.
  const arrows = [], dots = [];
  const dotGeo = new THREE.SphereGeometry(radius * 0.02, 12, 8);
  const dotMat = new THREE.MeshStandardMaterial({ color: 0xe01010 });
  let showContacts = true;
  function drawContacts(k) {
    const c = frames[k] ? frames[k].contacts : new Float32Array(0);
    const n = c.length / CONTACT;
    let shown = 0;
    for (let i = 0; i < n; i++) {
      if (!dots[i]) {
        dots[i] = new THREE.Mesh(dotGeo, dotMat);
        // Drawn over everything: a contact force points into the bodies that touch.
        arrows[i] = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, 0xff5500);
        for (const part of [arrows[i].line, arrows[i].cone]) {
          part.material.depthTest = false;
          part.renderOrder = 10;
        }
        scene.add(dots[i]);
        scene.add(arrows[i]);
      }
      const p = new THREE.Vector3(c[6 * i], c[6 * i + 1], c[6 * i + 2]);
      const f = new THREE.Vector3(c[6 * i + 3], c[6 * i + 4], c[6 * i + 5]);
      dots[i].position.copy(p);
      dots[i].visible = showContacts;
      const len = Math.min(f.length() * S.force_scale * radius, radius * 3);
      if (len > radius * 1e-3 && showContacts) {
        arrows[i].position.copy(p);
        arrows[i].setDirection(f.normalize());
        arrows[i].setLength(len, Math.min(len * 0.3, radius * 0.12), Math.min(len * 0.15, radius * 0.06));
        arrows[i].visible = true;
        shown++;
      } else {
        arrows[i].visible = false;
      }
    }
    for (let i = n; i < dots.length; i++) { dots[i].visible = false; arrows[i].visible = false; }
    state.arrows = shown;
    state.contacts = n;
  }

  // Side panel: title, status, joints.
  document.getElementById('title').textContent = S.model || '(unnamed model)';
  document.getElementById('source').textContent = S.source || '';
  const jointCells = [];
  const table = document.getElementById('joints');
  for (const j of S.joints) {
    const tr = document.createElement('tr');
    const name = document.createElement('td');
    name.textContent = j.name;
    const value = document.createElement('td');
    tr.append(name, value);
    table.appendChild(tr);
    jointCells.push(value);
  }
  function showJoints(k) {
    const f = frames[k];
    if (!f) return;
    S.joints.forEach((j, i) => {
      const v = Array.from(f.qpos.subarray(j.qpos_adr, j.qpos_adr + j.nq), (x) => x.toFixed(4));
      jointCells[i].textContent = v.join('\n');
    });
  }

  const slider = document.getElementById('time-slider');
  const playButton = document.getElementById('play');
  const speedSelect = document.getElementById('speed');
  const timeLabel = document.getElementById('time');
  const status = document.getElementById('status');

  const state = {
    ready: false, frame: 0, playing: false, renders: 0, arrows: 0, contacts: 0,
    live: !!config.live, received: 0, ended: false, errors,
  };
  let dirty = true;
  let playTime = 0, lastTick = null;
  let follow = !!config.live;

  function setFrame(k) {
    if (!frames.length) return;
    k = Math.max(0, Math.min(frames.length - 1, k | 0));
    state.frame = k;
    applyFrame(k);
    drawContacts(k);
    showJoints(k);
    slider.max = String(Math.max(frames.length - 1, 0));
    slider.value = String(k);
    timeLabel.textContent = `t = ${frames[k].time.toFixed(3)} s  (${k + 1}/${frames.length})`;
    dirty = true;
  }
  function setPlaying(on) {
    state.playing = on;
    playButton.textContent = on ? 'Pause' : 'Play';
    playButton.setAttribute('aria-label', on ? 'Pause' : 'Play');
    if (on) {
      if (state.frame >= frames.length - 1 && !config.live) setFrame(0);
      playTime = frames.length ? frames[state.frame].time : 0;
      lastTick = null;
    }
  }
  playButton.addEventListener('click', () => {
    if (config.live) { follow = !state.playing; }
    setPlaying(!state.playing);
  });
  slider.addEventListener('input', () => {
    follow = false;
    if (config.live && state.playing) setPlaying(false);
    setFrame(Number(slider.value));
  });
  const toggle = (id, fn) => document.getElementById(id).addEventListener('change', (e) => { fn(e.target.checked); dirty = true; });
  toggle('show-contacts', (on) => { showContacts = on; drawContacts(state.frame); });
  toggle('show-frames', (on) => linkAxes.forEach((o) => { o.visible = on; }));
  toggle('show-sites', (on) => siteMarks.forEach((o) => { o.visible = on; }));
  toggle('show-hidden', (on) => hiddenByDefault.forEach((o) => { o.visible = on; }));
  toggle('show-floor', (on) => floors.forEach((o) => { o.visible = on; }));
  controls.addEventListener('change', () => { dirty = true; });

  function resize() {
    const w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    dirty = true;
  }
  window.addEventListener('resize', resize);
  resize();

  function tick(now) {
    if (state.playing && frames.length && !config.live) {
      if (lastTick !== null) playTime += ((now - lastTick) / 1000) * Number(speedSelect.value);
      lastTick = now;
      let k = state.frame;
      while (k + 1 < frames.length && frames[k + 1].time <= playTime) k++;
      if (k !== state.frame) setFrame(k);
      if (k >= frames.length - 1) setPlaying(false);
    }
    if (dirty) {
      renderer.render(scene, camera);
      state.renders++;
      dirty = false;
      state.ready = true;
    }
    requestAnimationFrame(tick);
  }

  if (frames.length <= 1 && !config.live) {
    document.getElementById('controls').classList.add('hidden');
    document.body.classList.add('still');
    resize();
  }
  status.textContent = config.live ? 'live: waiting for frames…'
    : frames.length > 1 ? `${frames.length} frames, ${(frames[frames.length - 1].time - frames[0].time).toFixed(3)} s` : 'one state';
  setFrame(0);
  requestAnimationFrame(tick);

  if (config.live) {
    const source = new EventSource('events');
    source.addEventListener('frame', (e) => {
      const f = JSON.parse(e.data);
      addFrame(f.time, Float32Array.from(f.poses), Float32Array.from(f.qpos), Float32Array.from(f.contacts));
      state.received++;
      status.textContent = `live: ${state.received} frames received`;
      if (follow) setFrame(frames.length - 1); else slider.max = String(frames.length - 1);
    });
    source.addEventListener('end', () => {
      source.close();
      state.ended = true;
      status.textContent = `live: simulation ended, ${state.received} frames received`;
    });
    setPlaying(true);
  }

  // Projection of world points to page pixels (CSS px), for the tests.
  function project(p) {
    const v = new THREE.Vector3(p[0], p[1], p[2]).project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return [r.left + ((v.x + 1) / 2) * r.width, r.top + ((1 - v.y) / 2) * r.height];
  }
  function projectedBox() {
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    const b = new THREE.Box3();
    for (const m of robotMeshes) {
      if (!m.visible) continue;
      b.makeEmpty().expandByObject(m);
      for (let i = 0; i < 8; i++) {
        const [x, y] = project([i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z]);
        x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y);
      }
    }
    return { x0, y0, x1, y1 };
  }

  // Getters are defined on the state itself (Object.assign would copy their values once).
  Object.defineProperties(state, {
    nframes: { get: () => frames.length, enumerable: true },
    time: { get: () => (frames.length ? frames[state.frame].time : 0), enumerable: true },
  });
  window.lagrangeViewer = Object.assign(state, {
    setFrame, play: () => setPlaying(true), pause: () => setPlaying(false),
    project, projectedBox,
    canvas: () => { const r = renderer.domElement.getBoundingClientRect(); return { x: r.left, y: r.top, width: r.width, height: r.height }; },
    background: () => [background.r, background.g, background.b].map((x) => Math.round(255 * (x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055))),
    setFloor: (on) => { floors.forEach((o) => { o.visible = on; }); dirty = true; },
    revision: THREE.REVISION,
  });
})();
