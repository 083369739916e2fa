// A sheet: its drawing (the planner's SVG) with the live head position drawn in it while it
// cuts, in the drawing's sheet group, so it lands where the program's X and Y are.
import { h } from "./dom";

const SVG_NS = "http://www.w3.org/2000/svg";

export class SheetView {
  readonly element: HTMLElement;
  private head: SVGCircleElement;

  // The drawing is put in the page itself (not an <img>), so the screen's style applies to it:
  // the planner draws for 1:1 print, and its 0.8 mm strokes vanish on a 2.5 m sheet shown
  // 600 px wide. Scripts in it would not run (a parsed document's scripts never do, and the
  // console's Content-Security-Policy allows none inline).
  constructor(url: string, title: string) {
    this.head = document.createElementNS(SVG_NS, "circle");
    this.head.setAttribute("r", "12");
    this.head.setAttribute("class", "head");
    this.head.style.display = "none";
    this.element = h("div", { class: "sheet-frame", "aria-label": title });
    fetch(url, { credentials: "same-origin" })
      .then((r) => (r.ok ? r.text() : Promise.reject(new Error(`HTTP ${r.status}`))))
      .then((text) => {
        const doc = new DOMParser().parseFromString(text, "image/svg+xml");
        const svg = document.importNode(doc.documentElement, true) as unknown as SVGSVGElement;
        if (svg.nodeName !== "svg") throw new Error("not an SVG drawing");
        svg.removeAttribute("width");
        svg.removeAttribute("height");
        svg.classList.add("sheet-drawing");
        // The head is drawn in the sheet's own frame (the group that flips Y), on top.
        (svg.querySelector("#sheet") ?? svg).append(this.head);
        this.element.append(svg);
      })
      .catch((e) => this.element.append(h("p", { class: "form-error" }, `drawing: ${(e as Error).message}`)));
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
