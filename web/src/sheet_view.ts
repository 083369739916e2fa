// A sheet: its drawing (the planner's SVG) with the live head position drawn over it while it
// cuts. The drawing's frame is read off the SVG itself (its viewBox, and the sheet group's
// flip), so the overlay lands where the program's X and Y are.
import { h } from "./dom";

const SVG_NS = "http://www.w3.org/2000/svg";

export class SheetView {
  readonly element: HTMLElement;
  private head: SVGCircleElement;
  private overlay: SVGSVGElement;

  constructor(url: string, title: string) {
    const img = h("img", { src: url, alt: title, class: "sheet-drawing" });
    this.overlay = document.createElementNS(SVG_NS, "svg");
    this.overlay.setAttribute("class", "sheet-overlay");
    const group = document.createElementNS(SVG_NS, "g");
    this.head = document.createElementNS(SVG_NS, "circle");
    this.head.setAttribute("r", "12");
    this.head.setAttribute("class", "head");
    this.head.style.display = "none";
    group.append(this.head);
    this.overlay.append(group);
    this.element = h("div", { class: "sheet-frame" }, img, this.overlay);
    fetch(url, { credentials: "same-origin" })
      .then((r) => r.text())
      .then((text) => {
        const doc = new DOMParser().parseFromString(text, "image/svg+xml");
        const root = doc.documentElement;
        const box = root.getAttribute("viewBox");
        if (box) this.overlay.setAttribute("viewBox", box);
        const sheet = doc.getElementById("sheet");
        if (sheet?.getAttribute("transform")) group.setAttribute("transform", sheet.getAttribute("transform")!);
      })
      .catch(() => undefined);
  }

  // Program coordinates (mm); null hides the head.
  showHead(x_mm: number | null, y_mm: number | null): void {
    if (x_mm === null || y_mm === null) {
      this.head.style.display = "none";
      return;
    }
    this.head.style.display = "";
    this.head.setAttribute("cx", String(x_mm));
    this.head.setAttribute("cy", String(y_mm));
  }
}
