// A sheet's program in 3D (three.js): the tool tip's path (cuts dark, rapids faint), the tool
// axis drawn as a line up from the tip on the 5-axis moves, the sheet as a slab, and, while it
// cuts, the live head. The tip and axis come from the program's X Y Z A C through the head of the
// plan's report (kinematics.ts), so a pivot program (grblHAL, G93) shows where the jet is, not
// where the pivot is.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { h } from "./dom";
import { parseProgram, type ParsedProgram } from "./gcode";
import { type Head, toolAxis, toolTip } from "./kinematics";

export interface SheetSize {
  length_mm: number; // x
  width_mm: number; // y
  thickness_mm: number;
}

// Enough tool-axis lines to read the tilt along every contour, few enough to stay readable.
const kMaxAxisLines = 1500;

function segments(points: number[], colour: number, opacity = 1): THREE.LineSegments {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(points, 3));
  const material = new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1, opacity });
  return new THREE.LineSegments(geometry, material);
}

export class ToolpathView {
  readonly element: HTMLElement;
  private renderer: THREE.WebGLRenderer;
  private scene = new THREE.Scene();
  private camera = new THREE.PerspectiveCamera(40, 1, 0.1, 100000);
  private controls: OrbitControls;
  private headLine: THREE.Line;
  private axisLength_mm: number;
  private disposed = false;

  constructor(url: string, private head: Head, sheet: SheetSize) {
    // preserveDrawingBuffer: the browser test reads the canvas' pixels back.
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.setSize(720, 480);
    this.scene.background = new THREE.Color(0xf4f4f0);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener("change", () => this.draw());
    this.axisLength_mm = Math.max(4 * sheet.thickness_mm, 20);
    const headGeometry = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]);
    this.headLine = new THREE.Line(headGeometry, new THREE.LineBasicMaterial({ color: 0xd62728, linewidth: 3 }));
    this.headLine.visible = false;
    this.scene.add(this.slab(sheet), this.headLine);
    this.element = h("div", { class: "toolpath3d" }, this.renderer.domElement);
    fetch(url, { credentials: "same-origin" })
      .then((r) => (r.ok ? r.text() : Promise.reject(new Error(`HTTP ${r.status}`))))
      .then((text) => this.show(parseProgram(text, head)))
      .catch((e) => this.element.append(h("p", { class: "form-error" }, `program: ${(e as Error).message}`)));
  }

  dispose(): void {
    this.disposed = true;
    this.controls.dispose();
    this.renderer.dispose();
    this.renderer.forceContextLoss(); // browsers hold few WebGL contexts; give this one back now
  }

  // The live head from the machine's position (program coordinates, degrees); null hides it.
  showHead(p: { x_mm: number; y_mm: number; z_mm: number; a_deg: number; c_deg: number } | null): void {
    this.headLine.visible = p !== null;
    if (p) {
      const axis = toolAxis(p.a_deg, p.c_deg, this.head);
      const tip = toolTip(p.x_mm, p.y_mm, p.z_mm, axis, this.head);
      const nozzle = tip.map((v, i) => v + 2 * this.axisLength_mm * axis[i]);
      this.headLine.geometry.setFromPoints([new THREE.Vector3(...tip), new THREE.Vector3(...nozzle)]);
    }
    this.draw();
  }

  private slab(sheet: SheetSize): THREE.Object3D {
    const box = new THREE.BoxGeometry(sheet.length_mm, sheet.width_mm, sheet.thickness_mm);
    box.translate(sheet.length_mm / 2, sheet.width_mm / 2, -sheet.thickness_mm / 2); // top face at z 0
    const group = new THREE.Group();
    group.add(new THREE.Mesh(box, new THREE.MeshBasicMaterial({ color: 0xb8c4cc, transparent: true, opacity: 0.25, depthWrite: false })));
    group.add(new THREE.LineSegments(new THREE.EdgesGeometry(box), new THREE.LineBasicMaterial({ color: 0x7a8a96 })));
    return group;
  }

  private show(program: ParsedProgram): void {
    if (this.disposed) return;
    const cuts: number[] = [], rapids: number[] = [], axes: number[] = [];
    const bounds = new THREE.Box3();
    const tilted = program.moves.filter((m, i) => i > 0 && !m.rapid && m.tilted).length;
    const every = Math.max(1, Math.ceil(tilted / kMaxAxisLines));
    let tiltedSeen = 0;
    for (let i = 1; i < program.moves.length; ++i) {
      const from = program.moves[i - 1].tip, m = program.moves[i];
      (m.rapid ? rapids : cuts).push(...from, ...m.tip);
      if (m.rapid) continue;
      bounds.expandByPoint(new THREE.Vector3(...m.tip));
      if (m.tilted && tiltedSeen++ % every === 0) axes.push(...m.tip, ...m.tip.map((v, k) => v + this.axisLength_mm * m.axis[k]));
    }
    this.scene.add(segments(rapids, 0x9aa5ad, 0.6), segments(cuts, 0x1f3b73), segments(axes, 0xf28e2b, 0.8));
    // What the browser test reads: the counts, and where the tip cut (mm, the sheet's frame).
    Object.assign(this.element.dataset, {
      moves: String(program.moves.length),
      cuts: String(cuts.length / 6),
      tilted: String(tilted),
      axisLines: String(axes.length / 6),
      arcs: String(program.arcs),
      cutBounds: JSON.stringify(bounds.isEmpty() ? null : { min: bounds.min.toArray(), max: bounds.max.toArray() }),
    });
    this.frame(bounds.isEmpty() ? new THREE.Box3(new THREE.Vector3(), new THREE.Vector3(100, 100, 10)) : bounds);
  }

  private frame(bounds: THREE.Box3): void {
    const centre = bounds.getCenter(new THREE.Vector3());
    const size = Math.max(bounds.getSize(new THREE.Vector3()).length(), 50);
    this.camera.position.copy(centre).add(new THREE.Vector3(size * 0.5, -size * 0.9, size * 0.6));
    this.controls.target.copy(centre);
    this.controls.update();
    this.draw();
  }

  private draw(): void {
    if (!this.disposed) this.renderer.render(this.scene, this.camera);
  }
}
