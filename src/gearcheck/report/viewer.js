// gearcheck's 3D view (appended to three.js in one inline module by gearcheck/report/viewer.py,
// which defines ROOT_ID and the THREE namespace before this code). Nothing here loads anything:
// the geometry is the JSON in the container's script element of class "gc3d-data".
const root = document.getElementById(ROOT_ID);
const data = JSON.parse(root.querySelector("script.gc3d-data").textContent);
const stage = root.querySelector(".gc3d-stage");
const canvas = root.querySelector("canvas");
const tag = root.querySelector(".gc3d-tag");
const status = root.querySelector(".gc3d-status");
const select = root.querySelector("select");
const frameBar = root.querySelector(".gc3d-frames");
const slider = root.querySelector("input[type=range]");
const frameOut = root.querySelector("output");
const playButton = root.querySelector(".gc3d-play");
const cutLabel = root.querySelector(".gc3d-cut");
const cutBox = cutLabel.querySelector("input");

function fallback(reason) {
  root.querySelector(".gc3d-fallback").hidden = false;
  root.querySelector(".gc3d-why").textContent = reason;
  stage.hidden = true;
  root.querySelector(".gc3d-bar").hidden = true;
  frameBar.hidden = true;
  root.dataset.rendered = "fallback";
}

function webgl2() {
  try {
    return !!document.createElement("canvas").getContext("webgl2");
  } catch (e) {
    return false;
  }
}

function bytes(text) {
  const bin = atob(text);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out.buffer;
}

function matrix(m, scale) {  // row-major 16 numbers (mm) and a scale about the part's origin
  const out = new THREE.Matrix4().set(...m);
  if (scale !== undefined && scale !== 1) out.multiply(new THREE.Matrix4().makeScale(scale, scale, scale));
  return out;
}

function start() {
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({canvas, antialias: true, preserveDrawingBuffer: true});
  } catch (e) {
    fallback("WebGL could not start in this browser (" + e.message + ").");
    return;
  }
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.setClearColor(0xf4f6f9, 1);
  renderer.localClippingEnabled = true;
  const cut = new THREE.Plane();  // a worst pose's section: what lies on the camera's side is cut away
  const cuts = [cut];
  canvas.addEventListener("webglcontextlost", (e) => {
    e.preventDefault();
    fallback("the browser dropped the WebGL context.");
  });

  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(30, 4 / 3, 0.1, 1e5);
  camera.up.set(0, 0, 1);
  scene.add(camera);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x5a6070, 1.6));
  const head = new THREE.DirectionalLight(0xffffff, 2.2);
  head.position.set(0.35, 0.6, 1);
  camera.add(head, head.target);  // a headlight: the side turned to the viewer is lit
  head.target.position.set(0, 0, -1);

  const geometries = data.meshes.map((m) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(new Float32Array(bytes(m.v)), 3));
    g.setIndex(new THREE.BufferAttribute(m.u16 ? new Uint16Array(bytes(m.i)) : new Uint32Array(bytes(m.i)), 1));
    g.computeVertexNormals();
    g.computeBoundingBox();
    return g;
  });
  const edges = geometries.map((g) => new THREE.EdgesGeometry(g, 35));

  const parts = data.parts.map((p) => {
    const material = new THREE.MeshStandardMaterial({
      color: new THREE.Color().setRGB(p.c[0], p.c[1], p.c[2], THREE.SRGBColorSpace),
      metalness: 0.2, roughness: 0.55, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    const mesh = new THREE.Mesh(geometries[p.m], material);
    const lines = new THREE.LineSegments(edges[p.m], new THREE.LineBasicMaterial({color: 0x30343c, transparent: true,
      opacity: 0.45}));
    // the inside of a part a section cuts open, drawn darker
    const inside = new THREE.Mesh(geometries[p.m], new THREE.MeshStandardMaterial({
      color: material.color.clone().multiplyScalar(0.45), metalness: 0, roughness: 0.9, side: THREE.BackSide}));
    inside.visible = false;
    mesh.add(lines, inside);
    mesh.name = p.n;
    mesh.matrixAutoUpdate = false;
    scene.add(mesh);
    return {name: p.n, mesh, lines, inside, color: material.color.clone(), built: matrix(p.p),
      box: geometries[p.m].boundingBox};
  });
  const byName = new Map(parts.map((p) => [p.name, p]));
  // patches painted on parts (contact patterns): children of their part, so they move with it
  for (const o of data.overlays || []) {
    const host = byName.get(o.h);
    if (!host) continue;
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(new Float32Array(bytes(o.v)), 3));
    g.setIndex(new THREE.BufferAttribute(o.u16 ? new Uint16Array(bytes(o.i)) : new Uint32Array(bytes(o.i)), 1));
    g.computeVertexNormals();
    const paint = new THREE.Mesh(g, new THREE.MeshStandardMaterial({
      color: new THREE.Color().setRGB(o.c[0], o.c[1], o.c[2], THREE.SRGBColorSpace), metalness: 0,
      roughness: 0.6, side: THREE.DoubleSide}));
    paint.name = o.n;
    host.mesh.add(paint);
  }

  // closest-point markers: round dots of a fixed size on screen, drawn over everything
  const dot = document.createElement("canvas");
  dot.width = dot.height = 64;
  const ctx = dot.getContext("2d");
  ctx.beginPath();
  ctx.arc(32, 32, 26, 0, 2 * Math.PI);
  ctx.fillStyle = "#ffffff";
  ctx.fill();
  ctx.lineWidth = 8;
  ctx.strokeStyle = "#101010";
  ctx.stroke();
  // red (on the first part) drawn larger under blue (on the second): both show when they meet
  const texture = new THREE.CanvasTexture(dot);
  const gapGeometry = new THREE.BufferGeometry();
  gapGeometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(6), 3));
  const dots = [[0xd91a1a, 17], [0x1a4de6, 10]].map(([color, size], k) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3), 3));
    const points = new THREE.Points(g, new THREE.PointsMaterial({color, size, sizeAttenuation: false, map: texture,
      alphaTest: 0.5, depthTest: false}));
    points.renderOrder = 11 + k;
    points.frustumCulled = false;
    return points;
  });
  const gap = new THREE.Line(gapGeometry, new THREE.LineBasicMaterial({color: 0xe08a00, depthTest: false}));
  gap.renderOrder = 10;
  gap.frustumCulled = false;
  scene.add(gap, ...dots);
  function mark(a, b) {
    gap.visible = dots[0].visible = dots[1].visible = !!(a && b);
    if (!a || !b) return;
    gapGeometry.attributes.position.array.set([...a, ...b]);
    gapGeometry.attributes.position.needsUpdate = true;
    dots[0].geometry.attributes.position.array.set(a);
    dots[1].geometry.attributes.position.array.set(b);
    dots.forEach((d) => { d.geometry.attributes.position.needsUpdate = true; });
  }

  function worldBox(names, poses) {
    const box = new THREE.Box3();
    for (const p of parts) {
      if (names && !names.includes(p.name)) continue;
      const m = poses && poses[p.name] ? matrix(poses[p.name]) : p.built;
      box.union(p.box.clone().applyMatrix4(m));
    }
    return box;
  }

  // a sample of the parts' vertices in the world (at most about 20000 per pose), to frame a view on
  const totalVertices = parts.reduce((n, p) => n + p.mesh.geometry.attributes.position.count, 0);
  const stride = Math.max(1, Math.ceil(totalVertices / 20000));
  function worldPoints(names, poses, out) {
    for (const p of parts) {
      if (names && !names.includes(p.name)) continue;
      const m = poses && poses[p.name] ? matrix(poses[p.name]) : p.built;
      const a = p.mesh.geometry.attributes.position;
      for (let i = 0; i < a.count; i += stride) out.push(new THREE.Vector3().fromBufferAttribute(a, i).applyMatrix4(m));
    }
    return out;
  }

  // orbit camera: target, distance, azimuth about +z, elevation
  const view = {target: new THREE.Vector3(), dist: 1, az: -1.0, el: 0.45};
  let home = {...view, target: view.target.clone()};
  const sceneBox = worldBox();
  const sceneRadius = sceneBox.getBoundingSphere(new THREE.Sphere()).radius || 1;
  const scenePoints = worldPoints(null, null, []);
  const motionPoints = [...scenePoints];  // everything the motion frames sweep through
  for (const f of data.frames) worldPoints(null, f.poses, motionPoints);

  function place() {
    const c = Math.cos(view.el);
    camera.position.set(c * Math.cos(view.az), c * Math.sin(view.az), Math.sin(view.el))
      .multiplyScalar(view.dist).add(view.target);
    camera.near = Math.max(view.dist / 500, 1e-4);
    camera.far = view.dist + 4 * sceneRadius;
    camera.lookAt(view.target);
    camera.updateProjectionMatrix();
  }

  // point the camera from ``direction`` (default: the starting one) at ``center`` so that the
  // sphere of ``radius`` fills the view, or, given ``points``, so that they fill it (centred on
  // them, a small margin); that camera is what Reset restores
  function frame(center, radius, direction, points) {
    const dir = direction ? direction.clone().normalize() : new THREE.Vector3(
      Math.cos(0.45) * Math.cos(-1.0), Math.cos(0.45) * Math.sin(-1.0), Math.sin(0.45));
    view.az = Math.hypot(dir.x, dir.y) > 1e-3 ? Math.atan2(dir.y, dir.x) : -1.0;
    view.el = THREE.MathUtils.clamp(Math.asin(THREE.MathUtils.clamp(dir.z, -1, 1)), -1.55, 1.55);
    const tanV = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2));
    const tanH = tanV * camera.aspect;
    if (points && points.length) {
      const right = new THREE.Vector3().crossVectors(dir, camera.up).normalize().negate();
      const up = new THREE.Vector3().crossVectors(right, dir).normalize().negate();
      const lo = [Infinity, Infinity, Infinity];
      const hi = [-Infinity, -Infinity, -Infinity];
      for (const p of points) {
        const q = [p.dot(right), p.dot(up), p.dot(dir)];
        for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], q[k]); hi[k] = Math.max(hi[k], q[k]); }
      }
      const mid = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
      view.target.copy(right).multiplyScalar(mid[0]).addScaledVector(up, mid[1]).addScaledVector(dir, mid[2]);
      let need = 0;
      for (const p of points) {
        const q = p.clone().sub(view.target);
        const depth = q.dot(dir);
        need = Math.max(need, depth + Math.abs(q.dot(right)) / tanH, depth + Math.abs(q.dot(up)) / tanV);
      }
      view.dist = 1.06 * need;
    } else {
      view.target.copy(center);
      view.dist = radius / Math.sin(Math.atan(Math.min(tanV, tanH)));
    }
    home = {...view, target: view.target.clone()};
  }

  let current = null;  // the view's data: {kind, pose} (pose: a worst pose or a frame)
  let pending = false;
  let first = true;

  function render() {
    pending = false;
    place();
    renderer.render(scene, camera);
    if (current && current.kind === "worst" && current.pose.a) {
      const mid = new THREE.Vector3(...current.pose.a).add(new THREE.Vector3(...current.pose.b)).multiplyScalar(0.5);
      const ndc = mid.project(camera);
      const inside = Math.abs(ndc.x) <= 1 && Math.abs(ndc.y) <= 1 && ndc.z < 1;
      tag.hidden = !inside;
      tag.style.left = ((ndc.x + 1) / 2 * stage.clientWidth) + "px";
      tag.style.top = ((1 - ndc.y) / 2 * stage.clientHeight) + "px";
    } else {
      tag.hidden = true;
    }
    if (first) {
      first = false;
      root.dataset.renderMs = String(Math.round(performance.now()));  // since the page started loading
      root.dataset.rendered = "1";
    }
  }

  function redraw() {
    if (!pending) {
      pending = true;
      requestAnimationFrame(render);
    }
  }

  function pose(poses, scales) {
    for (const p of parts) {
      const m = poses && poses[p.name] ? matrix(poses[p.name], scales ? scales[p.name] : 1) : p.built;
      p.mesh.matrix.copy(m);
      p.mesh.matrixWorldNeedsUpdate = true;
    }
  }

  const red = new THREE.Color(0xd91a1a);
  const blue = new THREE.Color(0x1a4de6);
  function look(highlight, section) {
    const planes = section ? cuts : [];
    for (const p of parts) {
      const faded = highlight && !highlight.includes(p.name);
      const m = p.mesh.material;
      m.transparent = faded;
      m.opacity = faded ? 0.14 : 1;
      m.depthWrite = !faded;
      // a hint of the marker's colour tells the pair apart (red dot on the first, blue on the second)
      const hint = highlight && highlight[0] === p.name ? red : highlight && highlight[1] === p.name ? blue : null;
      m.color.copy(p.color);
      if (hint) m.color.lerp(hint, 0.2);
      p.inside.material.color.copy(m.color).multiplyScalar(0.45);
      p.inside.visible = !!section && !faded;
      m.clippingPlanes = p.lines.material.clippingPlanes = p.inside.material.clippingPlanes = planes;
      m.needsUpdate = p.lines.material.needsUpdate = p.inside.material.needsUpdate = true;
      p.lines.material.opacity = faded ? 0.06 : 0.45;
    }
  }

  function fmt(x) {  // a B-rep distance below a nanometre is a touch
    return Math.abs(x) < 1e-6 ? "0" : Math.abs(x) < 1e-3 ? x.toExponential(2) : x.toFixed(4);
  }

  function show(choice, keepCamera) {
    stopPlaying();
    const [kind, index] = choice.split(":");
    mark(null, null);
    frameBar.hidden = kind !== "frames";
    if (kind === "worst") {
      const w = data.worst[+index];
      current = {kind, pose: w};
      pose(w.poses, w.scales);
      cutLabel.hidden = !w.cut;
      if (w.cut) cut.setFromNormalAndCoplanarPoint(new THREE.Vector3(-w.cut[3], -w.cut[4], -w.cut[5]),
        new THREE.Vector3(w.cut[0], w.cut[1], w.cut[2]));
      look(w.parts, w.cut && cutBox.checked);
      const names = w.parts || [];
      let text = `${w.label}: ${names.join(" and ")} highlighted`;
      if (w.a && w.b) {
        mark(w.a, w.b);
        tag.textContent = w.d === null ? "" : `${fmt(w.d)} mm`;
        text += `; closest points ${w.d === null ? "" : fmt(w.d) + " mm apart "}(red on ${names[0]}, blue on ${names[1]})`;
        if (!keepCamera) {
          const a = new THREE.Vector3(...w.a);
          const b = new THREE.Vector3(...w.b);
          const center = a.clone().add(b).multiplyScalar(0.5);
          // gearcheck.report.camera chose the direction and the size of the region (as the pictures)
          const radius = w.r;
          const [az, el] = w.dir;
          const dir = new THREE.Vector3(Math.cos(el) * Math.cos(az), Math.cos(el) * Math.sin(az), Math.sin(el));
          frame(center, radius, dir);
        }
      } else if (!keepCamera) {
        frame(null, 0, null, worldPoints(names, w.poses, []));
      }
      status.textContent = text + (w.note ? `. ${w.note}` : "");
    } else if (kind === "frames") {
      current = {kind};
      cutLabel.hidden = true;
      look(null, false);
      showFrame(+slider.value);
      if (!keepCamera) frame(null, 0, null, motionPoints);
    } else {
      current = {kind: "built"};
      pose(null);
      cutLabel.hidden = true;
      look(null, false);
      status.textContent = `As built: ${parts.length} parts at their built poses.`;
      if (!keepCamera) frame(null, 0, null, scenePoints);
    }
    redraw();
  }

  function showFrame(i) {
    const f = data.frames[i];
    pose(f.poses, f.scales);
    frameOut.textContent = f.label;
    status.textContent = `Motion, ${data.frames_label}: ${f.label} (frame ${i + 1} of ${data.frames.length}).`;
    redraw();
  }

  let timer = null;
  function stopPlaying() {
    if (timer !== null) clearInterval(timer);
    timer = null;
    if (playButton) playButton.textContent = "Play";
  }
  if (playButton) {
    playButton.addEventListener("click", () => {
      if (timer !== null) {
        stopPlaying();
        return;
      }
      playButton.textContent = "Pause";
      timer = setInterval(() => {
        slider.value = String((+slider.value + 1) % data.frames.length);
        showFrame(+slider.value);
      }, 180);
    });
  }
  if (slider) slider.addEventListener("input", () => { stopPlaying(); showFrame(+slider.value); });
  select.addEventListener("change", () => show(select.value, false));
  cutBox.addEventListener("change", () => show(select.value, true));
  root.querySelector(".gc3d-reset").addEventListener("click", () => {
    Object.assign(view, home, {target: home.target.clone()});
    redraw();
  });

  // pointer: drag turns, shift-drag / right-drag / middle-drag pans, wheel or pinch zooms
  const pointers = new Map();
  let mode = "turn";
  function pan(dx, dy) {
    const scale = 2 * view.dist * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) / stage.clientHeight;
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    view.target.addScaledVector(right, -dx * scale).addScaledVector(up, dy * scale);
  }
  function turn(dx, dy) {
    view.az -= dx * 0.008;
    view.el = THREE.MathUtils.clamp(view.el + dy * 0.008, -1.55, 1.55);
  }
  function zoom(factor) {
    view.dist = THREE.MathUtils.clamp(view.dist * factor, sceneRadius * 1e-4, sceneRadius * 50);
  }
  canvas.addEventListener("pointerdown", (e) => {
    canvas.setPointerCapture(e.pointerId);
    pointers.set(e.pointerId, {x: e.clientX, y: e.clientY});
    mode = e.button === 1 || e.button === 2 || e.shiftKey ? "pan" : "turn";
    e.preventDefault();
  });
  canvas.addEventListener("pointermove", (e) => {
    const last = pointers.get(e.pointerId);
    if (!last) return;
    const dx = e.clientX - last.x;
    const dy = e.clientY - last.y;
    if (pointers.size === 2) {
      const [p, q] = [...pointers.entries()];
      const other = p[0] === e.pointerId ? q[1] : p[1];
      const before = Math.hypot(last.x - other.x, last.y - other.y);
      const after = Math.hypot(e.clientX - other.x, e.clientY - other.y);
      if (before > 0 && after > 0) zoom(before / after);
      pan(dx / 2, dy / 2);
    } else if (mode === "pan") {
      pan(dx, dy);
    } else {
      turn(dx, dy);
    }
    pointers.set(e.pointerId, {x: e.clientX, y: e.clientY});
    redraw();
  });
  const release = (e) => pointers.delete(e.pointerId);
  canvas.addEventListener("pointerup", release);
  canvas.addEventListener("pointercancel", release);
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    zoom(Math.exp(THREE.MathUtils.clamp(e.deltaY, -200, 200) * 0.0015));
    redraw();
  }, {passive: false});
  canvas.addEventListener("keydown", (e) => {
    const step = 12;
    const keys = {ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step]};
    if (keys[e.key]) {
      (e.shiftKey ? pan : turn)(...keys[e.key]);
    } else if (e.key === "+" || e.key === "=") {
      zoom(0.85);
    } else if (e.key === "-" || e.key === "_") {
      zoom(1 / 0.85);
    } else if (e.key === "r" || e.key === "R") {
      Object.assign(view, home, {target: home.target.clone()});
    } else {
      return;
    }
    e.preventDefault();
    redraw();
  });

  function resize() {
    const w = Math.max(stage.clientWidth, 1);
    const h = Math.max(stage.clientHeight, 1);
    renderer.setSize(w, h, false);
    const aspect = w / h;
    if (Math.abs(aspect - camera.aspect) > 1e-3) {
      camera.aspect = aspect;
      show(select.value, first === false);
    }
    redraw();
  }
  new ResizeObserver(resize).observe(stage);
  camera.aspect = Math.max(stage.clientWidth, 1) / Math.max(stage.clientHeight, 1);
  renderer.setSize(Math.max(stage.clientWidth, 1), Math.max(stage.clientHeight, 1), false);
  show(select.value, false);
}

if (webgl2()) {
  start();
} else {
  fallback("this browser offers no WebGL 2, which the 3D view needs.");
}
