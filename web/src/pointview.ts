// The scan's points in 3-D (three.js): orbit with the mouse, point size, colour by scan colour, by layer
// (original grey, synthesized cyan, object orange, filled from another station green) or by height; the picked
// cell's point is marked.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { FLAG_FROM_STATION, FLAG_OBJECT, FLAG_SYNTHESIZED, MeshData, PointSet, selectPoints } from './api';

export type PointColouring = 'rgb' | 'layers' | 'height';
export type Layer = 'original' | 'synthesized' | 'object' | 'from-stations';

// The layer a point belongs to: the object, filled from another station of the site (a real measurement),
// synthesized (filled, or on the surface behind a kept object), or the original scan.
export function layerOf(flag: number): Layer {
  if (flag & FLAG_OBJECT) return 'object';
  if (flag & FLAG_FROM_STATION) return 'from-stations';
  return flag & (FLAG_SYNTHESIZED | 4) ? 'synthesized' : 'original';
}

// The points of the layers not hidden (the same object when none is).
export function visiblePoints(points: PointSet, hidden: Set<Layer>): PointSet {
  if (hidden.size === 0) return points;
  const keep: number[] = [];
  for (let i = 0; i < points.count; ++i) if (!hidden.has(layerOf(points.flags[i]))) keep.push(i);
  return selectPoints(points, keep);
}

// Where the ray image's centre looks: the point (scanner frame) of the cell nearest the image's centre cell
// that has one; null without points.
export function centrePoint(points: PointSet): [number, number, number] | null {
  const row = Math.floor(points.rows / 2),
    col = Math.floor(points.cols / 2);
  let best = -1,
    bestDistance = Infinity;
  for (let i = 0; i < points.count; ++i) {
    if (points.flags[i] & 4) continue; // the layer behind: not what the scanner saw
    const r = Math.floor(points.cells[i] / points.cols),
      c = points.cells[i] % points.cols;
    const distance = Math.abs(r - row) + Math.abs(c - col);
    if (distance < bestDistance) [best, bestDistance] = [i, distance];
  }
  return best < 0 ? null : [points.xyz[3 * best], points.xyz[3 * best + 1], points.xyz[3 * best + 2]];
}

// Per-point colours (0..1 RGB) for a colouring mode.
export function pointColours(points: PointSet, mode: PointColouring): Float32Array {
  const colours = new Float32Array(points.count * 3);
  let zMin = Infinity,
    zMax = -Infinity;
  if (mode === 'height') {
    for (let i = 0; i < points.count; ++i) {
      zMin = Math.min(zMin, points.xyz[3 * i + 2]);
      zMax = Math.max(zMax, points.xyz[3 * i + 2]);
    }
  }
  for (let i = 0; i < points.count; ++i) {
    let r = points.rgb[3 * i] / 255,
      g = points.rgb[3 * i + 1] / 255,
      b = points.rgb[3 * i + 2] / 255;
    if (mode === 'layers') {
      const flag = points.flags[i];
      [r, g, b] =
        flag & FLAG_OBJECT
          ? [1, 0.55, 0.1]
          : flag & FLAG_FROM_STATION
            ? [0.35, 0.9, 0.3]
            : flag & FLAG_SYNTHESIZED
              ? [0.1, 0.9, 1]
              : [0.6, 0.6, 0.6];
    } else if (mode === 'height') {
      const t = zMax > zMin ? (points.xyz[3 * i + 2] - zMin) / (zMax - zMin) : 0.5;
      [r, g, b] = [t, 0.3 + 0.4 * (1 - Math.abs(2 * t - 1)), 1 - t];
    }
    colours.set([r, g, b], 3 * i);
  }
  return colours;
}

export class PointView {
  onPick: (cell: number) => void = () => {};
  // The user stopped moving the camera (an orbit, a pan or a zoom ended): main.ts then refines where it looks.
  onSettled: () => void = () => {};
  private renderer: THREE.WebGLRenderer;
  private scene = new THREE.Scene();
  private camera = new THREE.PerspectiveCamera(60, 1, 0.05, 2000);
  private controls: OrbitControls;
  private cloud: THREE.Points | null = null;
  private marker = new THREE.Mesh(
    new THREE.SphereGeometry(0.08),
    new THREE.MeshBasicMaterial({ color: 0xffff00 }),
  );
  private points: PointSet | null = null; // the points shown (the visible layers)
  private all: PointSet | null = null; // every point of the scan
  private hidden = new Set<Layer>();
  private model: THREE.Mesh | null = null;
  private mode: PointColouring = 'rgb';
  private size = 2;

  constructor(private container: HTMLElement) {
    this.renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(1);
    container.appendChild(this.renderer.domElement);
    // Scanner frame: z up; the camera starts at the scanner looking along +y.
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(0, -2, 2);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.set(0, 8, 0);
    this.controls.addEventListener('change', () => this.render());
    this.controls.addEventListener('end', () => this.onSettled());
    this.marker.visible = false;
    this.scene.add(this.marker);
    this.renderer.domElement.addEventListener('dblclick', (event) => this.pickAt(event));
    new ResizeObserver(() => this.resize()).observe(container);
  }

  // Shows or hides one layer (original / synthesized / object); the camera stays.
  setLayerVisible(layer: Layer, visible: boolean) {
    if (visible) this.hidden.delete(layer);
    else this.hidden.add(layer);
    if (this.all) this.show(this.all, true);
  }

  show(all: PointSet, keepCamera: boolean) {
    this.all = all;
    const points = visiblePoints(all, this.hidden);
    this.points = points;
    if (this.cloud) {
      this.scene.remove(this.cloud);
      this.cloud.geometry.dispose();
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(points.xyz, 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(pointColours(points, this.mode), 3));
    this.cloud = new THREE.Points(
      geometry,
      new THREE.PointsMaterial({ size: this.size, sizeAttenuation: false, vertexColors: true }),
    );
    this.scene.add(this.cloud);
    if (!keepCamera) {
      // From the scanner (the frame's origin), looking where the ray image's centre looks; orbiting turns
      // about that point. A scan without a point there falls back to a view of the whole cloud.
      const centre = centrePoint(all);
      if (centre && Math.hypot(...centre) > 0.1) {
        this.camera.position.set(0, 0, 0);
        this.controls.target.set(...centre);
      } else {
        geometry.computeBoundingSphere();
        const sphere = geometry.boundingSphere!;
        this.controls.target.copy(sphere.center);
        this.camera.position.set(
          sphere.center.x,
          sphere.center.y - sphere.radius * 0.9,
          sphere.center.z + sphere.radius * 0.5,
        );
      }
      this.controls.update();
    }
    this.render();
  }

  setColouring(mode: PointColouring) {
    this.mode = mode;
    if (this.points && this.cloud) {
      this.cloud.geometry.setAttribute(
        'color',
        new THREE.BufferAttribute(pointColours(this.points, mode), 3),
      );
      this.render();
    }
  }

  setPointSize(size: number) {
    this.size = size;
    if (this.cloud) (this.cloud.material as THREE.PointsMaterial).size = size;
    this.render();
  }

  // Shows a model mesh (parseMesh) placed by `scannerFromModel` (column-major 4x4), coloured by how
  // consistent its pose is (green consistent, red not, grey unknown).
  showModel(mesh: MeshData, scannerFromModel: number[], consistency: number | null) {
    if (!this.model) {
      this.model = new THREE.Mesh(
        new THREE.BufferGeometry(),
        new THREE.MeshBasicMaterial({ transparent: true, opacity: 0.55, side: THREE.DoubleSide }),
      );
      this.model.matrixAutoUpdate = false;
      this.scene.add(this.model);
    }
    if (this.model.userData.mesh !== mesh) {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(mesh.xyz, 3));
      geometry.setIndex(new THREE.BufferAttribute(mesh.indices, 1));
      this.model.geometry.dispose();
      this.model.geometry = geometry;
      this.model.userData.mesh = mesh;
    }
    this.model.matrix.fromArray(scannerFromModel);
    const colour =
      consistency === null
        ? new THREE.Color(0.7, 0.7, 0.7)
        : new THREE.Color(1 - consistency, consistency, 0.1);
    (this.model.material as THREE.MeshBasicMaterial).color = colour;
    this.render();
  }

  // The scene and a redraw, for what other modules draw in the view (stations.ts: the stations' markers), and
  // a turn of the view towards a point (the camera stays where it is).
  overlay(): { scene: THREE.Scene; render: () => void; focus: (x: number, y: number, z: number) => void } {
    return {
      scene: this.scene,
      render: () => this.render(),
      focus: (x, y, z) => {
        this.controls.target.set(x, y, z);
        this.controls.update();
        this.render();
      },
    };
  }

  // Where the camera is and the unit direction it looks along (scanner frame).
  view(): { eye: [number, number, number]; direction: [number, number, number] } {
    const direction = new THREE.Vector3();
    this.camera.getWorldDirection(direction);
    const eye = this.camera.position;
    return { eye: [eye.x, eye.y, eye.z], direction: [direction.x, direction.y, direction.z] };
  }

  // Orbits the camera about the target by `degrees` (tests and the "orbit" of the closing screenshots).
  orbit(degrees: number) {
    const offset = this.camera.position.clone().sub(this.controls.target);
    offset.applyAxisAngle(new THREE.Vector3(0, 0, 1), (degrees * Math.PI) / 180);
    this.camera.position.copy(this.controls.target).add(offset);
    this.controls.update();
    this.render();
  }

  // Marks the point of grid cell `cell` (row * cols + col), if it has one.
  highlight(cell: number) {
    if (!this.points) return;
    const index = this.points.cells.indexOf(cell);
    this.marker.visible = index >= 0;
    if (index >= 0)
      this.marker.position.set(
        this.points.xyz[3 * index],
        this.points.xyz[3 * index + 1],
        this.points.xyz[3 * index + 2],
      );
    this.render();
  }

  private pickAt(event: MouseEvent) {
    if (!this.cloud || !this.points) return;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const mouse = new THREE.Vector2(
      ((event.clientX - rect.left) / rect.width) * 2 - 1,
      -((event.clientY - rect.top) / rect.height) * 2 + 1,
    );
    const raycaster = new THREE.Raycaster();
    raycaster.params.Points = { threshold: 0.05 };
    raycaster.setFromCamera(mouse, this.camera);
    const hit = raycaster.intersectObject(this.cloud)[0];
    if (hit && hit.index !== undefined) {
      this.highlight(this.points.cells[hit.index]);
      this.onPick(this.points.cells[hit.index]);
    }
  }

  private resize() {
    const { clientWidth, clientHeight } = this.container;
    this.renderer.setSize(Math.max(1, clientWidth), Math.max(1, clientHeight));
    this.camera.aspect = Math.max(1, clientWidth) / Math.max(1, clientHeight);
    this.camera.updateProjectionMatrix();
    this.render();
  }

  private render() {
    this.renderer.render(this.scene, this.camera);
  }
}
