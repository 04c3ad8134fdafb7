// The page's own code (a classic script; `voronoi-fit view` inlines it). It loads the
// inlined three.js modules from blob URLs, decodes the inlined arrays and draws on demand
// (only when the view or a toggle changes), so a large crust costs nothing while idle.
// When the first frame is drawn it sets window.vfStats and body[data-vf-ready].
(async () => {
  const t0 = performance.now();
  const status = document.getElementById('vf-status');
  const fail = (e) => {
    console.error(e);
    const box = document.getElementById('vf-error');
    box.style.display = 'block';
    box.textContent = 'The viewer could not start: ' + (e && e.message ? e.message : e);
    document.body.dataset.vfReady = 'error';
  };
  try {
    const text = (id) => document.getElementById(id).textContent;
    const blobUrl = (src) => URL.createObjectURL(new Blob([src], { type: 'text/javascript' }));
    const coreUrl = blobUrl(text('vf-three-core'));
    const moduleSrc = text('vf-three-module');
    if (!moduleSrc.includes('"./three.core.min.js"')) throw new Error('unexpected three.module.min.js (import of ./three.core.min.js not found)');
    const moduleUrl = blobUrl(moduleSrc.replaceAll('"./three.core.min.js"', JSON.stringify(coreUrl)));
    const orbitSrc = text('vf-orbit').replace(/from\s*'three'/g, 'from ' + JSON.stringify(moduleUrl));
    const THREE = await import(moduleUrl);
    const { OrbitControls } = await import(blobUrl(orbitSrc));
    const tLibs = performance.now();

    const meta = JSON.parse(text('vf-meta'));
    const bytes = (id) => {
      const s = atob(text(id).trim());
      const out = new Uint8Array(s.length);
      for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
      return out.buffer;
    };
    const f32 = (id) => new Float32Array(bytes(id));
    const u32 = (id) => new Uint32Array(bytes(id));

    const canvas = document.getElementById('vf-canvas');
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true, alpha: true });
    renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    const scene = new THREE.Scene();
    const r = Math.max(meta.radius, 1e-9);
    const camera = new THREE.PerspectiveCamera(35, 1, r / 100, r * 100);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x8890a0, 1.2));
    const key = new THREE.DirectionalLight(0xffffff, 1.8);
    key.position.set(-0.5, 0.8, 1.0);
    camera.add(key);
    scene.add(camera);

    const meshOf = (m, color) => {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(f32(m.positions), 3));
      g.setIndex(new THREE.BufferAttribute(u32(m.indices), 1));
      g.computeBoundingSphere();
      const mat = new THREE.MeshLambertMaterial({ color, flatShading: true, side: THREE.DoubleSide });
      return new THREE.Mesh(g, mat);
    };
    const pointsOf = (id, color, size) => {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(f32(id), 3));
      return new THREE.Points(g, new THREE.PointsMaterial({ color, size, sizeAttenuation: false }));
    };
    const left = new THREE.Group();  // the input
    const right = new THREE.Group(); // the crust and everything fitted
    scene.add(left, right);
    const parts = {};
    if (meta.meshes.input) left.add(parts.input = meshOf(meta.meshes.input, 0xc8c2b8));
    if (meta.meshes.crust) right.add(parts.crust = meshOf(meta.meshes.crust, 0x56b4e9));
    if (meta.meshes.cells) {
      parts.cells = meshOf(meta.meshes.cells, 0x009e73);
      parts.cells.material = new THREE.MeshBasicMaterial({ color: 0x009e73, wireframe: true, transparent: true, opacity: 0.35 });
      right.add(parts.cells);
    }
    const pts = meta.points || {};
    if (pts.inside) right.add(parts.inside = pointsOf(pts.inside, 0x0072b2, 3));
    if (pts.outside) right.add(parts.outside = pointsOf(pts.outside, 0x999999, 3));
    if (pts.wrong) right.add(parts.wrong = pointsOf(pts.wrong, 0xd55e00, 3));
    const tBuilt = performance.now();

    const $ = (id) => document.getElementById(id);
    const toggles = { input: 'vf-show-input', crust: 'vf-show-crust', inside: 'vf-show-inside', outside: 'vf-show-outside', wrong: 'vf-show-wrong', cells: 'vf-show-cells' };
    for (const [part, id] of Object.entries(toggles)) {
      if (!parts[part]) { $(id).disabled = true; $(id).checked = false; $(id).parentElement.title = 'not available for this page'; }
    }
    const both = () => parts.input && (parts.crust || parts.cells);
    const layout = () => {
      for (const [part, id] of Object.entries(toggles)) if (parts[part]) parts[part].visible = $(id).checked;
      const side = $('vf-side').checked && both();
      const dx = side ? meta.extent[0] * 0.6 + r * 0.1 : 0;
      left.position.x = -dx;
      right.position.x = dx;
      if (parts.input) {
        const overlay = !side && parts.crust && parts.crust.visible;
        parts.input.material.transparent = overlay;
        parts.input.material.opacity = overlay ? 0.35 : 1;
        parts.input.material.depthWrite = !overlay;
      }
      for (const p of ['input', 'crust']) if (parts[p]) parts[p].material.wireframe = $('vf-wire').checked;
      return dx;
    };
    const frame = () => {
      const dx = layout();
      // Fit both halves: half-width dx + (most of) the radius, half-height the radius.
      const tanV = Math.tan((camera.fov * Math.PI) / 360);
      const halfW = dx + 0.8 * r, halfH = 0.8 * r;
      const dist = Math.max(halfH / tanV, halfW / (tanV * camera.aspect)) * 1.08 + 0.5 * r;
      const dir = new THREE.Vector3(0, 0.3, 1).normalize(); // straight on: both halves the same size
      camera.position.copy(dir.multiplyScalar(dist));
      controls.target.set(0, 0, 0);
      controls.update();
    };
    const controls = new OrbitControls(camera, canvas);
    let pending = false;
    let frames = 0;
    const draw = () => {
      pending = false;
      renderer.render(scene, camera);
      frames += 1;
      if (frames === 1) {
        const tFirst = performance.now();
        window.vfStats = {
          libs_ms: tLibs - t0, build_ms: tBuilt - tLibs, first_frame_ms: tFirst - t0,
          triangles: (meta.meshes.input ? meta.meshes.input.triangles : 0) + (meta.meshes.crust ? meta.meshes.crust.triangles : 0),
        };
        status.textContent = `${window.vfStats.triangles.toLocaleString('en')} triangles; first frame in ${Math.round(window.vfStats.first_frame_ms)} ms. Drag to orbit, right-drag to pan, wheel to zoom.`;
        document.body.dataset.vfReady = '1';
      }
    };
    const request = () => { if (!pending) { pending = true; requestAnimationFrame(draw); } };
    // For tests and measurements: the pieces, and one synchronous frame (ms) after
    // turning the view by `degrees` about the up axis.
    window.vfViewer = {
      THREE, renderer, scene, camera, controls,
      timedFrame: (degrees) => {
        camera.position.applyAxisAngle(new THREE.Vector3(0, 1, 0), (degrees * Math.PI) / 180);
        controls.update();
        const t = performance.now();
        renderer.render(scene, camera);
        renderer.getContext().readPixels(0, 0, 1, 1, 0x1908, 0x1401, new Uint8Array(4));
        return performance.now() - t;
      },
    };
    const resize = () => {
      const w = canvas.clientWidth, h = canvas.clientHeight;
      renderer.setSize(w, h, false);
      camera.aspect = w / Math.max(h, 1);
      camera.updateProjectionMatrix();
      request();
    };
    controls.addEventListener('change', request);
    for (const id of [...Object.values(toggles), 'vf-wire']) $(id).addEventListener('change', () => { layout(); request(); });
    $('vf-side').addEventListener('change', () => { frame(); request(); });
    if (pts.wrong) $('vf-show-wrong').parentElement.append(` (${pts.wrong_count.toLocaleString('en')} of ${pts.samples.toLocaleString('en')})`);
    $('vf-reset').addEventListener('click', () => { frame(); request(); });
    window.addEventListener('resize', resize);
    resize();
    frame();
  } catch (e) {
    fail(e);
  }
})();
