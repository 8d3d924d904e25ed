// The 3-D view, in the part's world millimetres with Z up: the part (triangles coloured once
// touched), the stock as machined (a translucent height field), the virtual tool, a ghost of the
// device's probe and the force as an arrow. Orbit, pan and zoom with the mouse.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const BACKGROUND = 0x16181c;
const UNTOUCHED = new THREE.Color(0x8a96a8);
const UNREACHABLE = new THREE.Color(0x4a4f58);
const TOUCHED = new THREE.Color(0x38c172);

export class Scene {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.renderer.setClearColor(BACKGROUND);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.1, 5000);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(80, -60, 70);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(40, -30, 80);
    this.scene.add(sun);
    this.touched = new Set();
    this.part = null;

    // The virtual tool: a ball end (its tip is the position) on a shank; the probe's ghost the same.
    this.tool = this.makeTool(0xe0a030, 1.0);
    this.probe = this.makeTool(0x60a0ff, 0.3);
    this.arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, 0xff5050, 1.2, 0.8);
    this.arrow.visible = false;
    this.scene.add(this.tool, this.probe, this.arrow);

    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
    const loop = () => {
      this.controls.update();
      this.renderer.render(this.scene, this.camera);
      requestAnimationFrame(loop);
    };
    loop();
  }

  makeTool(color, opacity, radius = 1.5) {
    const group = new THREE.Group();
    const material = new THREE.MeshStandardMaterial({ color, transparent: opacity < 1, opacity, depthWrite: opacity >= 1 });
    const ball = new THREE.Mesh(new THREE.SphereGeometry(radius, 20, 12), material);
    ball.position.z = radius;
    const shank = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, 12, 20), material);
    shank.rotation.x = Math.PI / 2;
    shank.position.z = radius + 6;
    group.add(ball, shank);
    group.userData.radius = radius;
    return group;
  }

  resize() {
    const width = Math.max(this.container.clientWidth, 1);
    const height = Math.max(this.container.clientHeight, 1);
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
  }

  setPart(part) {
    const positions = new Float32Array(part.vertices);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(positions.length), 3));
    geometry.computeVertexNormals();
    const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ vertexColors: true, side: THREE.DoubleSide,
      flatShading: true, metalness: 0.1, roughness: 0.7 }));
    this.part = { mesh, reachable: part.reachable, count: part.triangles };
    this.scene.add(mesh);
    for (let t = 0; t < part.triangles; t += 1) {
      this.colour(t);
    }
    geometry.attributes.color.needsUpdate = true;
    // The tools at the part's own cutter size.
    const radius = part.tool_diameter_mm / 2;
    for (const [name, color, opacity] of [['tool', 0xe0a030, 1.0], ['probe', 0x60a0ff, 0.3]]) {
      const old = this[name];
      this.scene.remove(old);
      this[name] = this.makeTool(color, opacity, radius);
      this[name].position.copy(old.position);
      this.scene.add(this[name]);
    }
    geometry.computeBoundingBox();
    const box = geometry.boundingBox;
    const centre = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    this.controls.target.copy(centre);
    this.camera.position.copy(centre.clone().add(new THREE.Vector3(0.9, -1.2, 1.0).multiplyScalar(size * 1.4)));
    this.controls.update();
  }

  colour(t) {
    const colors = this.part.mesh.geometry.attributes.color;
    const c = this.touched.has(t) ? TOUCHED : (this.part.reachable[t] ? UNTOUCHED : UNREACHABLE);
    for (let v = 0; v < 3; v += 1) {
      colors.setXYZ(3 * t + v, c.r, c.g, c.b);
    }
  }

  setTouched(ids, replace) {
    if (replace) {
      this.touched = new Set(ids);
    } else {
      ids.forEach((id) => this.touched.add(id));
    }
    if (this.part === null) {
      return;
    }
    if (replace) {
      for (let t = 0; t < this.part.count; t += 1) this.colour(t);
    } else {
      ids.forEach((id) => { if (id < this.part.count) this.colour(id); });
    }
    this.part.mesh.geometry.attributes.color.needsUpdate = true;
  }

  // The stock: one vertex per display cell at its centre, at the cell's height.
  setStock(grid) {
    if (this.stock) {
      this.scene.remove(this.stock);
      this.stock.geometry.dispose();
      this.stock = null;
    }
    if (!grid || grid.columns < 2 || grid.rows < 2) {
      return;
    }
    const { columns, rows } = grid;
    const positions = new Float32Array(columns * rows * 3);
    for (let r = 0; r < rows; r += 1) {
      for (let c = 0; c < columns; c += 1) {
        const i = r * columns + c;
        positions[3 * i] = grid.x0 + (c + 0.5) * grid.cell;
        positions[3 * i + 1] = grid.y0 + (r + 0.5) * grid.cell;
        positions[3 * i + 2] = grid.heights[i];
      }
    }
    const index = [];
    for (let r = 0; r + 1 < rows; r += 1) {
      for (let c = 0; c + 1 < columns; c += 1) {
        const a = r * columns + c;
        index.push(a, a + 1, a + columns, a + 1, a + columns + 1, a + columns);
      }
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    geometry.setIndex(index);
    geometry.computeVertexNormals();
    this.stock = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ color: 0xc8a070, transparent: true,
      opacity: 0.45, side: THREE.DoubleSide, depthWrite: false }));
    this.scene.add(this.stock);
  }

  updateStock(cells) {
    if (!this.stock || cells.length === 0) {
      return;
    }
    const positions = this.stock.geometry.attributes.position;
    for (const [i, height] of cells) {
      if (i < positions.count) positions.setZ(i, height);
    }
    positions.needsUpdate = true;
    this.stock.geometry.computeVertexNormals();
  }

  setTool(tool, probe, force) {
    this.tool.position.set(tool[0], tool[1], tool[2]);
    this.probe.position.set(probe[0], probe[1], probe[2]);
    const f = new THREE.Vector3(force[0], force[1], force[2]);
    const n = f.length();
    this.arrow.visible = n > 0.05;
    if (this.arrow.visible) {
      const start = new THREE.Vector3(tool[0], tool[1], tool[2] + this.tool.userData.radius);
      this.arrow.position.copy(start);
      this.arrow.setDirection(f.clone().normalize());
      this.arrow.setLength(2.0 * n + 1.0, 1.2, 0.8);  // 2 mm per newton
    }
  }

  // Of the view's pixels: how many differ from the background, and how many distinct colours.
  pixelStats() {
    const source = this.renderer.domElement;
    const canvas = document.createElement('canvas');
    canvas.width = source.width;
    canvas.height = source.height;
    const g = canvas.getContext('2d');
    g.drawImage(source, 0, 0);
    const data = g.getImageData(0, 0, canvas.width, canvas.height).data;
    const [br, bgc, bb] = [(BACKGROUND >> 16) & 0xff, (BACKGROUND >> 8) & 0xff, BACKGROUND & 0xff];
    let foreground = 0;
    const colours = new Set();
    for (let i = 0; i < data.length; i += 4) {
      if (Math.abs(data[i] - br) + Math.abs(data[i + 1] - bgc) + Math.abs(data[i + 2] - bb) > 12) {
        foreground += 1;
      }
      if (i % 64 === 0) colours.add((data[i] << 16) | (data[i + 1] << 8) | data[i + 2]);
    }
    return { width: canvas.width, height: canvas.height, foreground, colours: colours.size };
  }
}
