// The stations of a site (docs/stations.md "In the editor"): the list in the side panel (index, name, position,
// heading; the shown scan's station chosen, a click shows another), the stations in the 3-D view (a marker with
// its index at each, the current one highlighted; the other stations' points as a layer), and the tools that
// use them: Clean (what moved between the stations, removed and filled: one undoable edit per station, the
// removed cells of the shown station highlighted). The server holds the site (POST /api/sites, docs/api.md).
import * as THREE from 'three';
import { Api, DocumentInfo, JobInfo, Narrowed, PointSet, inverseRigid, multiply } from './api';
import type {
  CleanStationEntry,
  OpenedSiteReply,
  RemovedReply,
  SiteReply,
  StationEntry,
} from './api_types.generated';

// A station as GET /api/docs/ID/stations lists it: its position and heading come from its pose, which is finite
// (api.ts), so they are numbers here.
export type StationInfo = Narrowed<
  StationEntry,
  { position_m: [number, number, number]; heading_deg: number; world_from_scanner_column_major: number[] }
>;

// GET /api/docs/ID/stations (site null when the scan is in none) and POST /api/sites, which adds the scan to
// show and the reader's warnings.
export type SiteInfo = Narrowed<SiteReply, { stations: StationInfo[] }> & Partial<OpenedSiteReply>;

// One line of the list: "2 · station2 · (8.0, 2.0, 1.6) m · 30°".
export function stationLabel(station: StationInfo): string {
  const [x, y, z] = station.position_m.map((v) => v.toFixed(1));
  const name = station.name || `scan #${station.document}`;
  const closed = station.open ? '' : ' (closed)';
  return `${station.index} · ${name} · (${x}, ${y}, ${z}) m · ${Math.round(station.heading_deg)}°${closed}`;
}

// current_scanner_from_station (column-major 4x4): the 3-D view draws in the shown scan's scanner frame.
export function viewFromStation(current: number[], station: number[]): number[] {
  return multiply(inverseRigid(current), station);
}

// Where each station stands in the shown scan's scanner frame (metres).
export function stationPositionsInView(
  site: SiteInfo,
  worldFromCurrent: number[],
): [number, number, number][] {
  const currentFromWorld = inverseRigid(worldFromCurrent);
  return site.stations.map((station) => {
    const [x, y, z] = station.position_m;
    const m = currentFromWorld;
    return [
      m[0] * x + m[4] * y + m[8] * z + m[12],
      m[1] * x + m[5] * y + m[9] * z + m[13],
      m[2] * x + m[6] * y + m[10] * z + m[14],
    ];
  });
}

// The mean of `xyz` (3 per point), or null when empty.
export function centroid(xyz: Float32Array): [number, number, number] | null {
  const n = xyz.length / 3;
  if (n === 0) return null;
  const sum = [0, 0, 0];
  for (let i = 0; i < n; ++i) for (let k = 0; k < 3; ++k) sum[k] += xyz[3 * i + k];
  return [sum[0] / n, sum[1] / n, sum[2] / n];
}

// The positions (xyz, 3 per point) of the points of `points` whose cell is in `cells`: the removed cells
// highlighted (after a clean they hold the filled, synthesized points).
export function pointsOfCells(points: PointSet, cells: Iterable<number>): Float32Array {
  const wanted = new Set(cells);
  const out: number[] = [];
  for (let i = 0; i < points.count; ++i) {
    if (points.flags[i] & 4) continue; // the layer behind a kept object
    if (wanted.has(points.cells[i]))
      out.push(points.xyz[3 * i], points.xyz[3 * i + 1], points.xyz[3 * i + 2]);
  }
  return new Float32Array(out);
}

// The status line after a clean: the count here, then every station's, and who changed (each its own undo).
export function cleanSummary(result: Record<string, unknown> | undefined): string {
  if (!result || !Array.isArray(result.stations)) return 'clean: no result';
  const stations = result.stations as CleanStationEntry[];
  const here = Number(result.removed_cells ?? 0);
  const station = Number(result.station ?? -1);
  const per = stations
    .map((s) => `station ${s.station}: ${s.removed}${s.changed ? '' : s.why ? ` (${s.why})` : ''}`)
    .join(', ');
  const changed = stations.filter((s) => s.changed && s.station !== station).map((s) => `#${s.document}`);
  const others =
    changed.length > 0 ? ` Scans ${changed.join(', ')} were cleaned too: each has its own undo.` : '';
  return `clean: ${here} points removed here${station >= 0 ? ` (station ${station})` : ''} and filled; ${per}.${others}`;
}

// The status line after a fill from the other stations: the cells each gave, and what was synthesized.
export function fillSummary(result: Record<string, unknown> | undefined): string {
  if (!result || !Array.isArray(result.stations)) return 'fill from stations: no result';
  const per = (result.stations as { station: number; cells: number }[])
    .map((s) => `station ${s.station}: ${s.cells}`)
    .join(', ');
  return `fill from stations: ${Number(result.from_station_cells ?? 0)} of ${Number(result.hole_cells ?? 0)} cells from other stations (${per}), ${Number(result.synthesized_cells ?? 0)} synthesized`;
}

// What Fill from stations fills: the painted hole, else the object cut from the strokes, else the last cut.
export function fillHoleKind(doc: {
  hole_cells: number;
  object_stroke_cells: number;
  object_cells: number;
}): 'painted' | 'strokes' | 'object' {
  if (doc.hole_cells > 0) return 'painted';
  if (doc.object_stroke_cells > 0) return 'strokes';
  return 'object';
}

// Colours of the other stations' points, by station index.
const STATION_COLOURS = [0x4aa3ff, 0xffb347, 0x7ddc6a, 0xe07be0, 0xf2e35b, 0x5be0d2];

export interface StationsHost {
  api: Api;
  doc: () => DocumentInfo | null;
  show: (document: number) => Promise<void>; // shows another open scan
  status: (text: string) => void;
  runJob: (path: string, body: unknown, what: string) => Promise<JobInfo | null>;
  scene: THREE.Scene; // the 3-D view's scene (PointView.overlayScene)
  render: () => void; // redraws the 3-D view
  focus: (x: number, y: number, z: number) => void; // turns the 3-D view towards a point (shown scan's frame)
}

export class StationsPanel {
  site: SiteInfo | null = null;
  removedShown = 0; // points highlighted as removed by the last clean (tests)
  private markers = new THREE.Group();
  private others = new THREE.Group();
  private removed: THREE.Points | null = null;
  private othersVisible = false;
  private othersKey = '';

  constructor(
    private host: StationsHost,
    private list: HTMLElement,
    private cleanButton: HTMLButtonElement,
    private result: HTMLElement,
    private fillButton: HTMLButtonElement,
  ) {
    host.scene.add(this.markers, this.others);
    this.others.visible = false;
    cleanButton.addEventListener('click', () => this.clean());
    fillButton.addEventListener('click', () => this.fill());
  }

  // Opens a built-in scene or a file as a site (every station a scan of its own) and shows `station`.
  async open(body: { scene?: string; path?: string; documents?: number[] }) {
    this.host.status('opening the site…');
    const site = await this.host.api.json<SiteInfo>('/api/sites', {}, body);
    await this.host.show(site.document ?? site.stations[0].document);
    const warnings = (site.warnings ?? []).join(' ');
    this.host.status(`site ${site.name}: ${site.stations.length} stations. ${warnings}`);
  }

  // The shown scan changed (or its version): list its site's stations, draw them, highlight what a clean removed.
  async refresh(doc: DocumentInfo, points: PointSet | undefined) {
    const site = await this.host.api.json<SiteInfo>(`/api/docs/${doc.id}/stations`);
    if (this.host.doc()?.id !== doc.id) return;
    // A scan outside a site, before and after, has nothing of this panel in the 3-D view: no frame is drawn
    // for it (a frame of a million points takes most of a second without a GPU).
    const drawnBefore = this.site !== null || this.removed !== null;
    this.site = site.site === null ? null : site;
    this.drawList();
    this.drawMarkers(doc);
    await this.drawRemoved(doc, points);
    if (this.othersVisible) await this.drawOthers(doc);
    if (drawnBefore || this.site !== null || this.removed !== null) this.host.render();
  }

  // Shows or hides the other stations' points (the "other stations" layer).
  async setOthersVisible(visible: boolean) {
    this.othersVisible = visible;
    const doc = this.host.doc();
    if (visible && doc) await this.drawOthers(doc);
    this.others.visible = visible;
    this.host.render();
  }

  private drawList() {
    const site = this.site;
    this.cleanButton.disabled = !site || site.stations.filter((s) => s.open).length < 2;
    this.fillButton.disabled = this.cleanButton.disabled;
    if (!site) {
      this.list.replaceChildren(
        Object.assign(document.createElement('div'), {
          className: 'stations-none',
          textContent: 'not part of a site (open a file of several scans or a site scene as a site)',
        }),
      );
      return;
    }
    const items = site.stations.map((station) => {
      const item = document.createElement('li');
      item.className = `station${station.current ? ' current' : ''}${station.open ? '' : ' closed'}`;
      item.dataset.index = String(station.index);
      item.dataset.document = String(station.document);
      item.textContent = stationLabel(station);
      item.title =
        `${station.rows} x ${station.cols} cells, ${station.returns} returns; scan #${station.document}` +
        (station.removed_cells ? `; ${station.removed_cells} removed by the last clean` : '');
      if (station.open && !station.current)
        item.addEventListener('click', () => this.host.show(station.document));
      return item;
    });
    const list = document.createElement('ol');
    list.className = 'stations';
    list.replaceChildren(...items);
    this.list.replaceChildren(
      Object.assign(document.createElement('div'), { className: 'site-name', textContent: site.name }),
      list,
    );
  }

  private drawMarkers(doc: DocumentInfo) {
    for (const child of [...this.markers.children]) {
      this.markers.remove(child);
      disposeObject(child);
    }
    if (!this.site) return;
    const positions = stationPositionsInView(this.site, doc.world_from_scanner_column_major);
    this.site.stations.forEach((station, i) => {
      const colour = station.current ? 0xffee00 : STATION_COLOURS[station.index % STATION_COLOURS.length];
      // A tripod-like cone standing on the scanner's origin, and the index above it.
      const cone = new THREE.Mesh(
        new THREE.ConeGeometry(0.25, 0.6, 12),
        new THREE.MeshBasicMaterial({ color: colour }),
      );
      cone.rotation.x = Math.PI / 2; // three.js cones point along +y; the view's up is +z
      cone.position.set(positions[i][0], positions[i][1], positions[i][2] - 0.3);
      this.markers.add(cone);
      const label = textSprite(String(station.index), colour);
      label.position.set(positions[i][0], positions[i][1], positions[i][2] + 0.6);
      this.markers.add(label);
    });
  }

  private async drawRemoved(doc: DocumentInfo, points: PointSet | undefined) {
    if (this.removed) {
      this.host.scene.remove(this.removed);
      disposeObject(this.removed);
      this.removed = null;
    }
    this.removedShown = 0;
    const here = this.site?.stations.find((s) => s.current);
    if (!here || !here.removed_cells || !points) return;
    const { cells } = await this.host.api.json<RemovedReply>(`/api/docs/${doc.id}/removed`);
    const xyz = pointsOfCells(points, cells);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    this.removed = new THREE.Points(
      geometry,
      new THREE.PointsMaterial({ color: 0xff00ff, size: 4, sizeAttenuation: false }),
    );
    this.removedShown = xyz.length / 3;
    this.host.scene.add(this.removed);
  }

  // The other open stations' points, each in the shown scan's frame, coloured by station.
  private async drawOthers(doc: DocumentInfo) {
    const site = this.site;
    const others = site ? site.stations.filter((s) => !s.current && s.open) : [];
    const key = `${doc.id}:${others.map((s) => `${s.document}@${s.version}`).join(',')}`;
    if (key === this.othersKey) return;
    this.othersKey = key;
    for (const child of [...this.others.children]) {
      this.others.remove(child);
      disposeObject(child);
    }
    for (const station of others) {
      const points = await this.host.api.points(station.document);
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(points.xyz, 3));
      const cloud = new THREE.Points(
        geometry,
        new THREE.PointsMaterial({
          color: STATION_COLOURS[station.index % STATION_COLOURS.length],
          size: 1,
          sizeAttenuation: false,
        }),
      );
      cloud.matrixAutoUpdate = false;
      cloud.matrix.fromArray(
        viewFromStation(doc.world_from_scanner_column_major, station.world_from_scanner_column_major),
      );
      this.others.add(cloud);
    }
  }

  private async fill() {
    const doc = this.host.doc();
    if (!doc || !this.site) return;
    const finished = await this.host.runJob(
      `/api/docs/${doc.id}/fill-from-stations`,
      { hole: fillHoleKind(doc) },
      'fill from stations',
    );
    if (finished?.state === 'done') {
      const summary = fillSummary(finished.result);
      this.result.textContent = summary;
      this.host.status(summary);
    }
  }

  private async clean() {
    const doc = this.host.doc();
    if (!doc || !this.site) return;
    const finished = await this.host.runJob(`/api/docs/${doc.id}/clean`, {}, 'clean');
    if (finished?.state === 'done') {
      const summary = cleanSummary(finished.result);
      this.result.textContent = summary;
      this.host.status(summary);
      // The view turns towards what was removed here (highlighted).
      const position = this.removed?.geometry.getAttribute('position');
      const centre = position ? centroid(position.array as Float32Array) : null;
      if (centre) this.host.focus(...centre);
    }
  }
}

function textSprite(text: string, colour: number): THREE.Sprite {
  const canvas = document.createElement('canvas');
  canvas.width = 64;
  canvas.height = 64;
  const context = canvas.getContext('2d')!;
  context.fillStyle = 'rgba(0, 0, 0, 0.6)';
  context.beginPath();
  context.arc(32, 32, 30, 0, 2 * Math.PI);
  context.fill();
  context.fillStyle = `#${colour.toString(16).padStart(6, '0')}`;
  context.font = 'bold 40px sans-serif';
  context.textAlign = 'center';
  context.textBaseline = 'middle';
  context.fillText(text, 32, 34);
  const sprite = new THREE.Sprite(
    new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(canvas), depthTest: false }),
  );
  sprite.scale.set(0.8, 0.8, 1);
  return sprite;
}

function disposeObject(object: THREE.Object3D) {
  const withGeometry = object as THREE.Mesh;
  withGeometry.geometry?.dispose();
  const material = withGeometry.material as THREE.Material & { map?: THREE.Texture };
  material?.map?.dispose();
  material?.dispose();
}
