// The 3-D view of gale live: the slice (a texture coloured by speed), arrows and streamlines
// as vertex-coloured line lists, the rest meshes and colliders, the windicator and gust fronts,
// and the rake with two draggable ends. It only draws what the server computed (/api/field).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

// The colour map the server sends (viz::viridis at even stops) at s in [0, 1].
export function colourAt(map, s) {
  if (!map || !map.length) return [s, s, s];
  const x = Math.min(1, Math.max(0, Number.isFinite(s) ? s : 0)) * (map.length - 1);
  const i = Math.min(map.length - 2, Math.floor(x)), f = x - i;
  const a = map[i], b = map[i + 1];
  return [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])];
}

// The strain colour map of viz/strain.h (strainColour), the same constants: `base` at 0,
// yellow then red towards +top, teal towards −top, clamped beyond.
export const STRAIN_TOP = 0.25;
export function strainColour(strain, base, top = STRAIN_TOP) {
  const s = Number.isFinite(strain) && top > 0 ? Math.min(1, Math.max(-1, strain / top)) : 0;
  const mix = (a, b, w) => [a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2])];
  const yellow = [0.98, 0.82, 0.22], red = [0.86, 0.12, 0.1], teal = [0.2, 0.82, 0.72];
  if (s < 0) return mix(base, teal, -s);
  return s < 0.5 ? mix(base, yellow, 2 * s) : mix(yellow, red, 2 * s - 1);
}
export const CLOTH_BASE = [0.42, 0.6, 0.86];

export class View {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x15171b);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 500);
    this.camera.position.set(4, 3, 5);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.enableDamping = false;
    this.controls.addEventListener('change', () => this.render());
    this.scene.add(new THREE.HemisphereLight(0xdde6ff, 0x202428, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(3, 5, 4);
    this.scene.add(sun);
    this.groups = {};
    for (const name of ['slice', 'arrows', 'lines', 'rest', 'bodies', 'rigs', 'box', 'rake', 'sim', 'compare']) {
      this.groups[name] = new THREE.Group();
      this.scene.add(this.groups[name]);
    }
    this.rake = { a: null, b: null };
    this.onRakeMoved = null;
    this.setupRakeDrag();
    new ResizeObserver(() => this.resize()).observe(canvas.parentElement);
    this.resize();
  }

  resize() {
    const el = this.canvas.parentElement;
    const w = Math.max(50, el.clientWidth), h = Math.max(50, el.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }

  clear(name) {
    const g = this.groups[name];
    for (const c of [...g.children]) {
      g.remove(c);
      c.traverse((o) => {
        if (o.geometry) o.geometry.dispose();
        if (o.material) {
          if (o.material.map) o.material.map.dispose();
          o.material.dispose();
        }
      });
    }
  }

  setVisible(name, on) {
    this.groups[name].visible = on;
    if (name === 'bodies') {
      this.groups.rest.visible = on && this.groups.sim.children.length === 0;
      this.groups.sim.visible = on;
    }
    this.render();
  }

  // The box the field is shown in: a faint frame, and the camera aimed at its centre.
  setBox(box) {
    this.box = box;
    this.clear('box');
    const lo = new THREE.Vector3(...box.lo), hi = new THREE.Vector3(...box.hi);
    const size = hi.clone().sub(lo), mid = lo.clone().add(hi).multiplyScalar(0.5);
    const frame = new THREE.LineSegments(
      new THREE.EdgesGeometry(new THREE.BoxGeometry(size.x, size.y, size.z)),
      new THREE.LineBasicMaterial({ color: 0x3a404a }));
    frame.position.copy(mid);
    this.groups.box.add(frame);
    const axes = new THREE.AxesHelper(0.3 * Math.max(size.x, size.y, size.z));
    axes.position.copy(lo);
    this.groups.box.add(axes);
    if (!this.aimed) {
      this.aimed = true;
      const r = size.length();
      this.controls.target.copy(mid);
      this.camera.position.copy(mid).add(new THREE.Vector3(0.75 * r, 0.45 * r, 0.95 * r));
      this.controls.update();
    }
    if (!this.rake.a) {
      this.setRake([lo.x + 0.02 * size.x, lo.y + 0.1 * size.y, lo.z + 0.2 * size.z], [lo.x + 0.02 * size.x, hi.y - 0.1 * size.y, hi.z - 0.2 * size.z]);
    }
    this.render();
  }

  // The slice: a quad at axis = plane spanning bounds, textured with the speed colours.
  setSlice(s, map) {
    this.clear('slice');
    const data = new Uint8Array(4 * s.nu * s.nv);
    for (let row = 0; row < s.nv; ++row)
      for (let col = 0; col < s.nu; ++col) {
        const c = colourAt(map, s.speed[row * s.nu + col] / s.top);
        const k = 4 * ((s.nv - 1 - row) * s.nu + col); // texture row 0 is the bottom (v0)
        data[k] = Math.round(255 * c[0]);
        data[k + 1] = Math.round(255 * c[1]);
        data[k + 2] = Math.round(255 * c[2]);
        data[k + 3] = 255;
      }
    const tex = new THREE.DataTexture(data, s.nu, s.nv, THREE.RGBAFormat);
    tex.colorSpace = THREE.SRGBColorSpace;
    tex.magFilter = THREE.LinearFilter;
    tex.needsUpdate = true;
    const corner = (u, v) => {
      const p = [0, 0, 0];
      p[s.uAxis] = u;
      p[s.vAxis] = v;
      p[s.axis] = s.plane;
      return p;
    };
    const [u0, v0, u1, v1] = s.bounds;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(
      [...corner(u0, v0), ...corner(u1, v0), ...corner(u1, v1), ...corner(u0, v1)], 3));
    g.setAttribute('uv', new THREE.Float32BufferAttribute([0, 0, 1, 0, 1, 1, 0, 1], 2));
    g.setIndex([0, 1, 2, 0, 2, 3]);
    const m = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ map: tex, side: THREE.DoubleSide, transparent: true, opacity: 0.92 }));
    this.groups.slice.add(m);
  }

  // Arrows: a shaft and two head strokes each, length scaled so the fastest spans one cell.
  setArrows(a, map, top) {
    this.clear('arrows');
    if (!a.n) return;
    const box = this.box;
    const cell = Math.min(...[0, 1, 2].map((k) => (box.hi[k] - box.lo[k]) / a.n));
    const scale = a.max > 0 ? 0.9 * cell / a.max : 0;
    const pos = [], col = [];
    const P = a.positions, V = a.velocities;
    const up = new THREE.Vector3(), dir = new THREE.Vector3(), side = new THREE.Vector3(), tip = new THREE.Vector3();
    for (let i = 0; i < P.length; i += 3) {
      dir.set(V[i], V[i + 1], V[i + 2]);
      const speed = dir.length();
      if (!(speed > 1e-6 * a.max)) continue;
      const len = speed * scale;
      dir.multiplyScalar(1 / speed);
      const base = new THREE.Vector3(P[i], P[i + 1], P[i + 2]).addScaledVector(dir, -0.5 * len);
      tip.copy(base).addScaledVector(dir, len);
      up.set(0, 1, 0);
      if (Math.abs(dir.y) > 0.9) up.set(1, 0, 0);
      side.crossVectors(dir, up).normalize().multiplyScalar(0.12 * len);
      const back = tip.clone().addScaledVector(dir, -0.3 * len);
      const c = colourAt(map, speed / top);
      pos.push(base.x, base.y, base.z, tip.x, tip.y, tip.z,
        tip.x, tip.y, tip.z, back.x + side.x, back.y + side.y, back.z + side.z,
        tip.x, tip.y, tip.z, back.x - side.x, back.y - side.y, back.z - side.z);
      for (let k = 0; k < 6; ++k) col.push(...c);
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    this.groups.arrows.add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.7 })));
  }

  setStreamlines(lines, map, top) {
    this.clear('lines');
    const pos = [], col = [];
    for (const l of lines) {
      const p = l.points, s = l.speed;
      for (let k = 0; k + 1 < s.length; ++k) {
        pos.push(p[3 * k], p[3 * k + 1], p[3 * k + 2], p[3 * k + 3], p[3 * k + 4], p[3 * k + 5]);
        const a = colourAt(map, 0.25 + 0.75 * s[k] / top), b = colourAt(map, 0.25 + 0.75 * s[k + 1] / top);
        col.push(...a, ...b);
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    this.groups.lines.add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.85 })));
  }

  // A mesh (and its wireframe) or polylines; returns the mesh, if any.
  geometry(group, g, colour) {
    let mesh = null;
    if (g.triangles.length) {
      const geo = new THREE.BufferGeometry();
      geo.setAttribute('position', new THREE.Float32BufferAttribute(g.points, 3));
      geo.setIndex(g.triangles);
      geo.computeVertexNormals();
      mesh = new THREE.Mesh(geo, new THREE.MeshStandardMaterial({ color: colour, side: THREE.DoubleSide, roughness: 0.7, transparent: true, opacity: 0.9 }));
      group.add(mesh);
      const wire = new THREE.LineSegments(new THREE.WireframeGeometry(geo), new THREE.LineBasicMaterial({ color: 0x000000, transparent: true, opacity: 0.15 }));
      mesh.userData.wire = wire;
      group.add(wire);
    }
    if (g.polylines.length) {
      const pos = [];
      for (const line of g.polylines)
        for (let k = 0; k + 1 < line.length; ++k)
          pos.push(...g.points.slice(3 * line[k], 3 * line[k] + 3), ...g.points.slice(3 * line[k + 1], 3 * line[k + 1] + 3));
      const geo = new THREE.BufferGeometry();
      geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
      group.add(new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ color: 0xc08040 })));
    }
    return mesh;
  }

  // Rest meshes of the cloth and hair, and the colliders.
  setBodies(rest, colliders) {
    this.clear('bodies');
    this.clear('rest');
    const g = this.groups.bodies;
    for (const r of rest) this.geometry(this.groups.rest, r, 0x7fa8e8);
    this.colliders = [];
    for (const c of colliders) {
      const entry = { shape: c.shape, name: c.name, object: null, radius: c.radius, length: null };
      if (c.shape === 'mesh') {
        if (c.mesh) entry.object = this.geometry(g, c.mesh, 0x9aa0a8);
      } else {
        this.placeCollider(entry, c);
      }
      this.colliders.push(entry);
    }
  }

  // Puts an analytic collider's object where the pose says (made, or remade when a capsule's
  // length or a radius changes).
  placeCollider(entry, c) {
    const g = this.groups.bodies;
    const a = new THREE.Vector3(...c.a), b = new THREE.Vector3(...c.b);
    const len = a.distanceTo(b);
    const remake = !entry.object || entry.radius !== c.radius || (c.shape === 'capsule' && Math.abs(entry.length - len) > 1e-6);
    if (remake && entry.object) {
      g.remove(entry.object);
      entry.object.traverse((o) => { if (o.geometry) o.geometry.dispose(); if (o.material) o.material.dispose(); });
      entry.object = null;
    }
    const mat = () => new THREE.MeshStandardMaterial({ color: 0x9aa0a8, roughness: 0.8, transparent: true, opacity: 0.55 });
    if (c.shape === 'sphere') {
      if (!entry.object) entry.object = new THREE.Mesh(new THREE.SphereGeometry(c.radius, 32, 16), mat());
      entry.object.position.copy(a);
    } else if (c.shape === 'capsule') {
      if (!entry.object) entry.object = new THREE.Mesh(new THREE.CapsuleGeometry(c.radius, len, 8, 24), mat());
      entry.object.position.copy(a).add(b).multiplyScalar(0.5);
      if (len > 0) entry.object.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
    } else if (c.shape === 'plane') {
      const n = new THREE.Vector3(...c.normal).normalize();
      const size = this.box ? 2 * Math.max(...[0, 1, 2].map((k) => this.box.hi[k] - this.box.lo[k])) : 6;
      if (!entry.object) entry.object = new THREE.GridHelper(size, 20, 0x555b66, 0x30343c);
      entry.object.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), n);
      entry.object.position.copy(a);
    }
    entry.radius = c.radius;
    entry.length = len;
    if (entry.object && !entry.object.parent) g.add(entry.object);
  }

  // The colliders at one time (/api/colliders): analytic ones moved, mesh sequences' vertices
  // replaced (their triangles are those of /api/scene).
  setColliderPoses(list) {
    if (!this.colliders) return;
    list.forEach((c, i) => {
      const entry = this.colliders[i];
      if (!entry || entry.name !== c.name) return;
      if (c.shape !== 'mesh') {
        this.placeCollider(entry, c);
      } else if (c.points && entry.object) {
        const geo = entry.object.geometry, pos = geo.getAttribute('position');
        if (pos.array.length !== c.points.length) return;
        pos.array.set(c.points);
        pos.needsUpdate = true;
        geo.computeVertexNormals();
        geo.computeBoundingBox();
        geo.computeBoundingSphere();
        const wire = entry.object.userData.wire;
        wire.geometry.dispose();
        wire.geometry = new THREE.WireframeGeometry(geo);
      }
    });
    this.render();
  }

  // The screen rectangle (canvas pixels: x0, y0, x1, y1) of a collider's current bounds.
  screenBox(name) {
    const entry = (this.colliders || []).find((c) => c.name === name);
    const object = entry && entry.object ? entry.object : this.groups.sim.getObjectByName(name);
    if (!object) return null;
    const box = new THREE.Box3().setFromObject(object);
    const w = this.canvas.width, h = this.canvas.height;
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (let k = 0; k < 8; ++k) {
      const p = new THREE.Vector3(k & 1 ? box.max.x : box.min.x, k & 2 ? box.max.y : box.min.y, k & 4 ? box.max.z : box.min.z).project(this.camera);
      const x = (p.x + 1) / 2 * w, y = (1 - p.y) / 2 * h;
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
    }
    return [Math.max(0, Math.floor(x0)), Math.max(0, Math.floor(y0)), Math.min(w, Math.ceil(x1)), Math.min(h, Math.ceil(y1))];
  }

  // Simulated frame geometry (replaces the rest meshes while shown): coloured by strain (per
  // vertex, from /api/frame) when `strain` is on; grey when `stale` (a run an edit replaced).
  setSimFrame(objects, { strain = this.strainOn, stale = false } = {}) {
    this.clear('sim');
    this.simObjects = objects;
    this.strainOn = strain;
    for (const o of objects) {
      const mesh = this.geometry(this.groups.sim, o, stale ? 0x808080 : 0x8fc0ff);
      if (mesh) mesh.name = o.label;
      if (mesh && strain && !stale && o.strain && o.strain.length * 3 === o.points.length) {
        const col = new Float32Array(o.points.length);
        o.strain.forEach((x, i) => col.set(strainColour(x, CLOTH_BASE), 3 * i));
        mesh.geometry.setAttribute('color', new THREE.BufferAttribute(col, 3));
        mesh.material.vertexColors = true;
        mesh.material.color.set(0xffffff);
        mesh.material.needsUpdate = true;
      }
    }
    this.groups.rest.visible = objects.length === 0 && this.groups.bodies.visible;
    this.render();
  }

  // Another run's frame over the shown one (compare): its cloth as an orange wireframe, its
  // hair as orange lines; nothing for an empty list.
  setCompareFrame(objects) {
    this.clear('compare');
    const mat = new THREE.LineBasicMaterial({ color: 0xff9a3c, transparent: true, opacity: 0.8 });
    for (const o of objects) {
      const pos = [];
      const P = o.points;
      const seg = (i, j) => pos.push(P[3 * i], P[3 * i + 1], P[3 * i + 2], P[3 * j], P[3 * j + 1], P[3 * j + 2]);
      for (let k = 0; k + 2 < o.triangles.length; k += 3) {
        const [a, b, c] = [o.triangles[k], o.triangles[k + 1], o.triangles[k + 2]];
        seg(a, b); seg(b, c); seg(c, a);
      }
      for (const line of o.polylines) for (let k = 0; k + 1 < line.length; ++k) seg(line[k], line[k + 1]);
      const geo = new THREE.BufferGeometry();
      geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
      const lines = new THREE.LineSegments(geo, mat.clone());
      lines.name = 'compare:' + o.label;
      this.groups.compare.add(lines);
    }
    this.render();
  }

  // The windicator arrow (length by speed) at the box's upwind top corner, and each gust's
  // front and tail as planes across the box.
  setRigs(o) {
    this.clear('rigs');
    if (!this.box) return;
    const lo = new THREE.Vector3(...this.box.lo), hi = new THREE.Vector3(...this.box.hi);
    const mid = lo.clone().add(hi).multiplyScalar(0.5), size = hi.clone().sub(lo).length();
    if (o.windicator.present) {
      const d = new THREE.Vector3(...o.windicator.direction).normalize();
      const len = (0.12 + 0.2 * Math.min(1, o.windicator.speed / 15)) * size;
      const origin = new THREE.Vector3(mid.x, hi.y + 0.05 * size, mid.z).addScaledVector(d, -0.5 * len);
      this.groups.rigs.add(new THREE.ArrowHelper(d, origin, len, 0xf0a040, 0.25 * len, 0.12 * len));
    }
    for (const gust of o.gusts) {
      const d = new THREE.Vector3(...gust.direction).normalize();
      for (const [dist, opacity] of [[gust.front, 0.28], [gust.tail, 0.12]]) {
        // The plane x . d = dist, as a square around the box centre's projection on it.
        const c = mid.clone().addScaledVector(d, dist - mid.dot(d));
        if (c.distanceTo(mid) > 0.6 * size) continue;
        const m = new THREE.Mesh(new THREE.PlaneGeometry(size, size),
          new THREE.MeshBasicMaterial({ color: 0xff8a3c, transparent: true, opacity, side: THREE.DoubleSide, depthWrite: false }));
        m.position.copy(c);
        m.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), d);
        this.groups.rigs.add(m);
      }
    }
  }

  // The rake: a line between two draggable handles.
  setRake(a, b) {
    this.rake.a = new THREE.Vector3(...a);
    this.rake.b = new THREE.Vector3(...b);
    this.drawRake();
  }

  drawRake() {
    this.clear('rake');
    const size = this.box ? new THREE.Vector3(...this.box.hi).sub(new THREE.Vector3(...this.box.lo)).length() : 4;
    const g = new THREE.BufferGeometry().setFromPoints([this.rake.a, this.rake.b]);
    this.groups.rake.add(new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0xf0a040 })));
    this.handles = [];
    for (const key of ['a', 'b']) {
      const h = new THREE.Mesh(new THREE.SphereGeometry(0.018 * size, 16, 8), new THREE.MeshBasicMaterial({ color: 0xf0a040 }));
      h.position.copy(this.rake[key]);
      h.userData.key = key;
      this.groups.rake.add(h);
      this.handles.push(h);
    }
    this.render();
  }

  // Dragging a rake end moves it in the plane facing the camera through it.
  setupRakeDrag() {
    const ray = new THREE.Raycaster(), ndc = new THREE.Vector2(), plane = new THREE.Plane(), hit = new THREE.Vector3();
    let dragging = null;
    const toNdc = (e) => {
      const r = this.canvas.getBoundingClientRect();
      ndc.set(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1);
      ray.setFromCamera(ndc, this.camera);
    };
    this.canvas.addEventListener('pointerdown', (e) => {
      if (!this.handles || e.button !== 0) return;
      toNdc(e);
      const hits = ray.intersectObjects(this.handles);
      if (!hits.length) return;
      dragging = hits[0].object.userData.key;
      this.controls.enabled = false;
      plane.setFromNormalAndCoplanarPoint(this.camera.getWorldDirection(new THREE.Vector3()), this.rake[dragging]);
      this.canvas.setPointerCapture(e.pointerId);
      e.stopPropagation();
    }, true);
    this.canvas.addEventListener('pointermove', (e) => {
      if (!dragging) return;
      toNdc(e);
      if (ray.ray.intersectPlane(plane, hit)) {
        const lo = this.box.lo, hi = this.box.hi;
        hit.set(Math.min(hi[0], Math.max(lo[0], hit.x)), Math.min(hi[1], Math.max(lo[1], hit.y)), Math.min(hi[2], Math.max(lo[2], hit.z)));
        this.rake[dragging].copy(hit);
        this.drawRake();
      }
    });
    this.canvas.addEventListener('pointerup', () => {
      if (!dragging) return;
      dragging = null;
      this.controls.enabled = true;
      if (this.onRakeMoved) this.onRakeMoved();
    });
  }
}
