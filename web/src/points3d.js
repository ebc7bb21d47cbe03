// A rotatable 3D point cloud for Figure 7 (three.js, WebGL): every reading one GL point, so
// 50,000 readings draw in milliseconds even on a software renderer, where a glyph per marker
// (plotly's scatter3d) took tens of seconds. Drawn on demand (after a rotation, zoom or
// resize), never in a loop. The data sit in a unit cube (each axis scaled from its own range);
// the cube's edges, the axis titles and the ends of each axis's range are drawn around them.
//
//   const plot = createPoints3d(container, { title, axes: ['α °', 'β °', 'δ °'] });
//   plot.setPoints({ x, y, z, value, ids });  // Float64Array/arrays of equal length; value → colour
//   plot.onPick((index) => …);                // a click (not a drag) on a point
//   plot.count, plot.screenPosition(i)        // how many points; point i in client pixels
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { CSS2DRenderer, CSS2DObject } from 'three/addons/renderers/CSS2DRenderer.js';
import { el } from './dom.js';

// Viridis (matplotlib's), nine stops; values between are blended linearly.
const VIRIDIS = [[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141], [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]];

function viridis(t, out, k) {
  const f = Math.min(1, Math.max(0, t)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(f));
  const u = f - i;
  for (let c = 0; c < 3; c++) out[k + c] = (VIRIDIS[i][c] * (1 - u) + VIRIDIS[i + 1][c] * u) / 255;
}

function range(a) {
  let lo = Infinity, hi = -Infinity;
  for (let i = 0; i < a.length; i++) { if (a[i] < lo) lo = a[i]; if (a[i] > hi) hi = a[i]; }
  if (!(hi > lo)) { lo = (Number.isFinite(lo) ? lo : 0) - 1; hi = lo + 2; } // one value: ±1 around it
  return [lo, hi];
}

const OUTWARD = [[0, -0.12, 0], [0.12, 0, 0], [-0.12, -0.12, 0]];
const fmt = (v) => (Math.abs(v) >= 100 ? v.toFixed(0) : v.toFixed(1));

export function createPoints3d(container, { title, axes, height = 420 }) {
  container.classList.add('points3d');
  container.append(el('div', { class: 'points3d-title' }, title));
  const renderer = new THREE.WebGLRenderer({ antialias: false });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const labels = new CSS2DRenderer();
  labels.domElement.className = 'points3d-labels';
  const stage = el('div', { class: 'points3d-stage' });
  stage.append(renderer.domElement, labels.domElement);
  container.append(stage);

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);
  const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
  camera.up.set(0, 0, 1);
  camera.position.set(2.4, -1.5, 1.5);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.set(0.5, 0.5, 0.5);
  controls.update();

  const box = new THREE.LineSegments(new THREE.EdgesGeometry(new THREE.BoxGeometry(1, 1, 1)), new THREE.LineBasicMaterial({ color: 0x999999 }));
  box.position.set(0.5, 0.5, 0.5);
  scene.add(box);
  const geometry = new THREE.BufferGeometry();
  const cloud = new THREE.Points(geometry, new THREE.PointsMaterial({ size: 3, sizeAttenuation: false, vertexColors: true }));
  scene.add(cloud);
  const picked = new THREE.Points(new THREE.BufferGeometry(), new THREE.PointsMaterial({ size: 9, sizeAttenuation: false, color: 0xe63946 }));
  picked.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3), 3));
  picked.visible = false;
  scene.add(picked);
  const labelGroup = new THREE.Group();
  scene.add(labelGroup);

  let width = 0;
  let queued = false;
  function draw() {
    queued = false;
    renderer.render(scene, camera);
    labels.render(scene, camera);
  }
  function redraw() {
    if (!queued) { queued = true; requestAnimationFrame(draw); }
  }
  controls.addEventListener('change', redraw);
  function resize() {
    const w = Math.max(100, container.clientWidth);
    if (w === width) return;
    width = w;
    renderer.setSize(w, height);
    labels.setSize(w, height);
    camera.aspect = w / height;
    camera.updateProjectionMatrix();
    redraw();
  }
  new ResizeObserver(resize).observe(container);
  resize();

  function label(text, x, y, z, cls) {
    const o = new CSS2DObject(el('span', { class: cls }, text));
    o.position.set(x, y, z);
    labelGroup.add(o);
  }

  let positions = new Float32Array(0);
  let pickHandler = () => {};
  const api = {
    count: 0,
    setPoints({ x, y, z, value }) {
      const n = x.length;
      const ranges = [range(x), range(y), range(z)];
      const [vlo, vhi] = range(value);
      positions = new Float32Array(3 * n);
      const colors = new Float32Array(3 * n);
      const cols = [x, y, z];
      for (let i = 0; i < n; i++) {
        for (let a = 0; a < 3; a++) positions[3 * i + a] = (cols[a][i] - ranges[a][0]) / (ranges[a][1] - ranges[a][0]);
        viridis((value[i] - vlo) / (vhi - vlo), colors, 3 * i);
      }
      geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
      geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
      geometry.computeBoundingSphere();
      labelGroup.clear();
      // Each axis along one of the cube's edges: x along (t, 0, 0), y along (1, t, 0), z along
      // (0, 0, t); its title at the middle, the ends of its range at the corners.
      const edges = [(t) => [t, 0, 0], (t) => [1, t, 0], (t) => [0, 0, t]];
      for (let a = 0; a < 3; a++) {
        const at = edges[a];
        const mid = at(0.5), lo = at(0), hi = at(1);
        label(axes[a], ...mid, 'points3d-axis');
        // The range's ends a little outside the cube, away from the other axes' corner labels.
        const out = (p) => p.map((v, b) => v + OUTWARD[a][b]);
        label(fmt(ranges[a][0]), ...out(lo), 'points3d-tick');
        label(fmt(ranges[a][1]), ...out(hi), 'points3d-tick');
      }
      picked.visible = false;
      api.count = n;
      redraw();
    },
    onPick(handler) { pickHandler = handler; },
    // Marks point i (the reading shown below the plots).
    mark(i) {
      picked.geometry.attributes.position.array.set(positions.subarray(3 * i, 3 * i + 3));
      picked.geometry.attributes.position.needsUpdate = true;
      picked.visible = true;
      redraw();
    },
    screenPosition(i) {
      const v = new THREE.Vector3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]).project(camera);
      const r = renderer.domElement.getBoundingClientRect();
      return { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height };
    },
  };

  // A click picks the point nearest the ray within a few pixels; a drag rotates instead.
  const raycaster = new THREE.Raycaster();
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4 || api.count === 0) return;
    const r = renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2((e.clientX - r.left) / r.width * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(ndc, camera);
    // About 4 px at the cube's distance.
    raycaster.params.Points.threshold = 4 * camera.position.distanceTo(controls.target) * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) * 2 / height;
    const hits = raycaster.intersectObject(cloud);
    if (hits.length === 0) return;
    hits.sort((a, b) => a.distanceToRay - b.distanceToRay || a.distance - b.distance);
    api.mark(hits[0].index);
    pickHandler(hits[0].index);
  });
  container.points3d = api; // for tests: count, screenPosition
  return api;
}
