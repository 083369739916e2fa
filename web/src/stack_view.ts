// The planned stack in 3D (three.js): stack.stl with each layer in its own colour, the CAD model
// over it translucent, orbit and zoom, and a clipping plane to look at a section.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { STLLoader } from "three/examples/jsm/loaders/STLLoader.js";
import { h } from "./dom";

export interface LayerBand {
  z_bottom_mm: number;
  thickness_mm: number;
}

const kPalette = [0x4e79a7, 0xf28e2b, 0x59a14f, 0xe15759, 0x76b7b2, 0xedc948, 0xb07aa1, 0xff9da7, 0x9c755f, 0xbab0ac];

function colourByLayer(geometry: THREE.BufferGeometry, layers: LayerBand[]): void {
  const position = geometry.getAttribute("position");
  const colours = new Float32Array(position.count * 3);
  const colour = new THREE.Color();
  for (let i = 0; i < position.count; i += 3) {
    // A triangle takes the layer of its centre: a side face never straddles two colours.
    const z = (position.getZ(i) + position.getZ(i + 1) + position.getZ(i + 2)) / 3;
    let layer = layers.findIndex((l) => z >= l.z_bottom_mm - 1e-6 && z <= l.z_bottom_mm + l.thickness_mm + 1e-6);
    if (layer < 0) layer = 0;
    colour.setHex(kPalette[layer % kPalette.length]);
    for (let k = 0; k < 3; ++k) colour.toArray(colours, (i + k) * 3);
  }
  geometry.setAttribute("color", new THREE.BufferAttribute(colours, 3));
}

export class StackView {
  readonly element: HTMLElement;
  private renderer: THREE.WebGLRenderer;
  private scene = new THREE.Scene();
  private camera = new THREE.PerspectiveCamera(40, 1, 0.1, 100000);
  private controls: OrbitControls;
  private clip = new THREE.Plane(new THREE.Vector3(-1, 0, 0), 0);
  private disposed = false;

  constructor(stackUrl: string, modelUrl: string | null, layers: LayerBand[]) {
    // preserveDrawingBuffer: the browser test reads the canvas' pixels back.
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.localClippingEnabled = true;
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.setSize(720, 480);
    this.scene.background = new THREE.Color(0xf4f4f0);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x666666, 2.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, -2, 3);
    this.scene.add(sun);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener("change", () => this.draw());
    const slider = h("input", { type: "range", min: "0", max: "1000", value: "1000", "aria-label": "section" });
    slider.addEventListener("input", () => this.setSection(Number(slider.value) / 1000));
    this.element = h("div", { class: "stack3d" }, this.renderer.domElement, h("label", {}, "Section ", slider));
    this.load(stackUrl, modelUrl, layers);
  }

  dispose(): void {
    this.disposed = true;
    this.controls.dispose();
    this.renderer.dispose();
  }

  private bounds = new THREE.Box3();

  private async load(stackUrl: string, modelUrl: string | null, layers: LayerBand[]): Promise<void> {
    const loader = new STLLoader();
    const stack = await loader.loadAsync(stackUrl);
    if (this.disposed) return;
    colourByLayer(stack, layers);
    const stackMesh = new THREE.Mesh(stack, new THREE.MeshStandardMaterial({ vertexColors: true, clippingPlanes: [this.clip], side: THREE.DoubleSide }));
    this.scene.add(stackMesh);
    stack.computeBoundingBox();
    this.bounds.copy(stack.boundingBox!);
    this.frame();
    if (modelUrl) {
      // The model in its file's frame, moved onto the stack's (same footprint centre, same base).
      const model = await loader.loadAsync(modelUrl).catch(() => null);
      if (model && !this.disposed) {
        model.computeBoundingBox();
        const m = model.boundingBox!, s = this.bounds;
        model.translate((s.min.x + s.max.x - m.min.x - m.max.x) / 2, (s.min.y + s.max.y - m.min.y - m.max.y) / 2, s.min.z - m.min.z);
        const material = new THREE.MeshStandardMaterial({ color: 0x222222, transparent: true, opacity: 0.25, depthWrite: false, clippingPlanes: [this.clip] });
        this.scene.add(new THREE.Mesh(model, material));
      }
    }
    this.draw();
  }

  private frame(): void {
    const centre = this.bounds.getCenter(new THREE.Vector3());
    const size = this.bounds.getSize(new THREE.Vector3()).length();
    this.camera.position.copy(centre).add(new THREE.Vector3(size * 0.9, -size * 1.2, size * 0.8));
    this.controls.target.copy(centre);
    this.controls.update();
    this.setSection(1);
  }

  // 1: everything; smaller: the stack cut away beyond that fraction of its width.
  private setSection(fraction: number): void {
    const x = this.bounds.min.x + (this.bounds.max.x - this.bounds.min.x) * fraction;
    this.clip.constant = fraction >= 1 ? Number.MAX_VALUE : x;
    this.draw();
  }

  private draw(): void {
    if (!this.disposed) this.renderer.render(this.scene, this.camera);
  }
}
