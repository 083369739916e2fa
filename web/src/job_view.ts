// One job: what the operator must do now, its layers and deviation, the stack in 3D, its sheets
// (with the head drawn on the one that cuts), and its event log.
import { clear, duration, fmt, h, notify } from "./dom";
import type { Rpc } from "./rpc";
import { type Head, toolAxis, toolTip } from "./kinematics";
import { SheetView } from "./sheet_view";
import { StackView } from "./stack_view";
import { ToolpathView } from "./toolpath_view";
import type { Job, JobEvent, MachineStatus } from "./types";
import { progressOf } from "./queue_view";

interface Report {
  layers: { index: number; z_bottom_mm: number; thickness_mm: number; passes: number; max_deviation_mm: number; within_tolerance: boolean }[];
  shortfalls: { z_from_mm: number; z_to_mm: number; deviation_mm: number }[];
  warnings: string[];
  deviation: Record<string, { volume_pct: number; max_mm: number }>;
  settings: { strategy: string; tolerance_mm: number };
  cam?: { rtcp: boolean; head?: Omit<Head, "rtcp"> };
  sheets: { index: number; thickness_mm: number; width_mm: number; length_mm: number; material: string; slot?: string; estimated_time_s: number; parts: { layer: number }[] }[];
}

export class JobView {
  private report: Report | null = null;
  private stack: StackView | null = null;
  private sheets = new Map<number, SheetView>();
  // One 3D toolpath at a time: a browser holds few WebGL contexts, and a job may have many sheets.
  private toolpath: { sheet: number; view: ToolpathView } | null = null;
  private prompt = h("section", { class: "prompt", id: "prompt" });
  private head = h("section", { class: "job-head" });
  private events = h("section", { class: "events" });
  private body = h("div", {});

  constructor(readonly view: HTMLElement, private rpc: Rpc, readonly jobId: string, private role: string) {
    clear(view, this.head, this.prompt, this.body, this.events);
  }

  dispose(): void {
    this.stack?.dispose();
    this.toolpath?.view.dispose();
  }

  async update(job: Job): Promise<void> {
    this.renderHead(job);
    this.renderPrompt(job);
    if (!this.report && job.summary?.layers) await this.loadReport(job);
    void this.loadEvents();
  }

  // The head drawn where the jet is: a pivot program's X Y are the pivot's, up to pivot·sin A
  // (130 mm at 60°) away from the tip.
  machine(status: MachineStatus): void {
    const p = status.position;
    const cutting = status.job === this.jobId && p !== undefined && ["cutting", "paused"].includes(status.job_state ?? "");
    const head = this.machineHead();
    let tip: [number, number, number] | null = null;
    if (cutting && head) tip = toolTip(p!.x_mm, p!.y_mm, p!.z_mm, toolAxis(p!.a_deg, p!.c_deg, head), head);
    for (const [index, sheet] of this.sheets) sheet.showHead(tip && status.sheet === index ? tip[0] : null, tip && status.sheet === index ? tip[1] : null);
    if (this.toolpath) this.toolpath.view.showHead(cutting && status.sheet === this.toolpath.sheet ? p! : null);
  }

  // The head of the plan's report; null for a plan written before reports carried it.
  private machineHead(): Head | null {
    const cam = this.report?.cam;
    if (!cam) return null;
    if (cam.head) return { ...cam.head, rtcp: cam.rtcp };
    return cam.rtcp ? { pivot_mm: 0, a_sign: 1, c_sign: 1, c_offset_deg: 0, rtcp: true } : null;
  }

  private artefact(name: string): string {
    return `/api/jobs/${this.jobId}/${name}`;
  }

  private renderHead(job: Job): void {
    const p = progressOf(job);
    clear(
      this.head,
      h("h1", {}, job.name, " ", h("span", { class: `state ${job.state}`, id: "job-state" }, job.state.replace("_", " "))),
      h("progress", { max: "1", value: String(p.fraction) }),
      h("span", { class: "small", id: "job-progress" }, p.text),
      job.summary?.layers ? h("p", {}, `${job.summary.layers} layers on ${job.summary.sheets} sheets, ${job.summary.lines} lines, about ${duration(job.summary.estimated_cut_s)} of cutting`) : null,
    );
  }

  // What the person at the machine must do next, in words, with the button that does it.
  private renderPrompt(job: Job): void {
    const act = (method: string, params: object, label: string, cls = "big ok") =>
      h("button", { class: cls, onclick: () => this.rpc.call(method, params).catch((e) => notify(e.message)) }, label);
    const sheet = job.sheets?.find((s) => s.index === job.current_sheet);
    const planned = this.report?.sheets.find((s) => s.index === job.current_sheet);
    if (job.state === "waiting_sheet" && sheet) {
      const size = planned ? `${fmt(planned.length_mm, 0)} × ${fmt(planned.width_mm, 0)} mm` : "";
      clear(
        this.prompt,
        h("h2", {}, `Load sheet ${sheet.index} of ${job.sheets.length}`),
        h("p", { class: "large" }, `${fmt(sheet.thickness_mm, 1)} mm ${sheet.material} ${size}`),
        planned?.slot ? h("p", { class: "large slot", id: "prompt-slot" }, `from rack slot ${planned.slot}`) : null,
        h("div", { class: "prompt-drawing" }, new SheetView(this.artefact(`sheet-${sheet.index}.svg`), `sheet ${sheet.index}`).element),
        act("job.confirm_sheet", { job: job.id, sheet: sheet.index }, `Sheet ${sheet.index} is loaded: cut it`),
      );
    } else if (job.state === "paused") {
      clear(this.prompt, h("h2", {}, "Paused"), h("p", { class: "large" }, job.error || "held"), act("job.resume", { job: job.id }, "Resume"));
    } else if (job.state === "interrupted" && sheet) {
      clear(
        this.prompt,
        h("h2", {}, "Interrupted"),
        h("p", { class: "large" }, `${job.error || "the daemon stopped while cutting"} — sheet ${sheet.index} resumes at line ${sheet.resume_line} (contour ${sheet.contour}).`),
        act("job.resume", { job: job.id }, "Resume"),
      );
    } else if (job.state === "failed") {
      clear(this.prompt, h("h2", {}, "Failed"), h("p", { class: "large" }, job.error));
    } else {
      clear(this.prompt);
    }
    this.prompt.hidden = this.prompt.childElementCount === 0;
    if (this.role === "viewer") for (const b of Array.from(this.prompt.querySelectorAll("button"))) b.title = "an operator's action";
  }

  private async loadReport(job: Job): Promise<void> {
    const r = await fetch(this.artefact("report.json"), { credentials: "same-origin" });
    if (!r.ok) return;
    this.report = (await r.json()) as Report;
    const report = this.report;
    this.stack = new StackView(this.artefact("stack.stl"), /\.stl$/i.test(job.name) ? this.artefact("model") : null, report.layers);
    clear(
      this.body,
      h("h2", {}, "Layers"),
      layerTable(report),
      report.shortfalls.length ? h("p", { class: "warn-text" }, `Beyond tolerance: ${report.shortfalls.map((s) => `z ${fmt(s.z_from_mm)}–${fmt(s.z_to_mm)} mm (${fmt(s.deviation_mm, 2)} mm)`).join(", ")}`) : null,
      report.warnings.length ? h("ul", { class: "warnings", id: "plan-warnings" }, ...report.warnings.map((w) => h("li", { class: "warn-text" }, w))) : null,
      h("h2", {}, "Deviation from the model"),
      deviationChart(report),
      h("h2", {}, "Stack"),
      this.stack.element,
      h("h2", {}, "Sheets"),
      ...report.sheets.map((s) => this.sheetPanel(s)),
    );
    this.renderPrompt(job);
  }

  private sheetPanel(s: Report["sheets"][number]): HTMLElement {
    const view = new SheetView(this.artefact(`sheet-${s.index}.svg`), `sheet ${s.index}`);
    this.sheets.set(s.index, view);
    const place = h("div", { class: "toolpath-place" });
    const head = this.machineHead();
    const open = h("button", { class: "toolpath-open", onclick: () => this.openToolpath(s, place) }, "Toolpath in 3D");
    if (!head) {
      open.setAttribute("disabled", "");
      open.title = "planned before reports carried the head: plan it again to see its toolpath";
    }
    const slot = s.slot ? `, rack slot ${s.slot}` : "";
    return h(
      "article",
      { class: "sheet", "data-sheet": String(s.index) },
      h("h3", {}, `Sheet ${s.index}: ${fmt(s.thickness_mm, 1)} mm ${s.material}, ${fmt(s.length_mm, 0)} × ${fmt(s.width_mm, 0)} mm${slot}, ${s.parts.length} parts, about ${duration(s.estimated_time_s)}`),
      view.element,
      h("p", {}, open, " ", h("a", { href: this.artefact(`sheet-${s.index}.nc`), download: `sheet-${s.index}.nc` }, "program")),
      place,
    );
  }

  private openToolpath(s: Report["sheets"][number], place: HTMLElement): void {
    const head = this.machineHead();
    if (!head) return;
    if (this.toolpath) {
      this.toolpath.view.dispose();
      this.toolpath.view.element.remove();
      if (this.toolpath.sheet === s.index) {
        this.toolpath = null; // the button shows and hides
        return;
      }
    }
    const view = new ToolpathView(this.artefact(`sheet-${s.index}.nc`), head, s);
    this.toolpath = { sheet: s.index, view };
    place.append(view.element);
  }

  private async loadEvents(): Promise<void> {
    const events = await this.rpc.call<JobEvent[]>("job.events", { job: this.jobId }).catch(() => null);
    if (!events) return;
    clear(
      this.events,
      h("h2", {}, "Events"),
      h("ol", { class: "event-log" }, ...events.slice().reverse().map((e) => h("li", {}, `${new Date(e.t_unix_ms).toLocaleTimeString()} ${e.kind}: ${describe(e)}`))),
    );
  }
}

function describe(e: JobEvent): string {
  const d = e.data as Record<string, any>;
  if (e.kind === "state") return `${d.from ?? "–"} → ${d.to}${d.reason ? ` (${d.reason})` : ""}${d.by ? ` by ${d.by}` : ""}`;
  if (e.kind === "action") return `${d.action}${d.sheet ? ` sheet ${d.sheet}` : ""} by ${d.by} (${d.role})`;
  return JSON.stringify(d);
}

function layerTable(report: Report): HTMLElement {
  const sheetOf = (layer: number) => report.sheets.find((s) => s.parts.some((p) => p.layer === layer))?.index ?? "–";
  return h(
    "table",
    { class: "layers", id: "layers" },
    h("tr", {}, ...["Layer", "z (mm)", "Thickness (mm)", "Sheet", "Passes", "Deviation (mm)", "Within tolerance"].map((t) => h("th", {}, t))),
    ...report.layers.map((l) =>
      h("tr", { class: l.within_tolerance ? "" : "over" }, h("td", {}, l.index), h("td", {}, fmt(l.z_bottom_mm, 2)), h("td", {}, fmt(l.thickness_mm, 2)), h("td", {}, sheetOf(l.index)), h("td", {}, l.passes), h("td", {}, fmt(l.max_deviation_mm, 3)), h("td", {}, l.within_tolerance ? "yes" : "NO")),
    ),
  );
}

// Volume deviation of the three edge strategies side by side, the chosen one marked.
function deviationChart(report: Report): SVGSVGElement {
  const NS = "http://www.w3.org/2000/svg";
  const names = ["vertical", "sloped", "curved"].filter((n) => report.deviation[n]);
  const top = Math.max(...names.map((n) => report.deviation[n].volume_pct), 1e-9);
  const svg = document.createElementNS(NS, "svg");
  svg.setAttribute("viewBox", "0 0 420 170");
  svg.setAttribute("class", "deviation-chart");
  names.forEach((name, i) => {
    const d = report.deviation[name];
    const height = (d.volume_pct / top) * 110;
    const bar = document.createElementNS(NS, "rect");
    bar.setAttribute("x", String(30 + i * 130));
    bar.setAttribute("y", String(130 - height));
    bar.setAttribute("width", "90");
    bar.setAttribute("height", String(height));
    bar.setAttribute("class", name === report.settings.strategy ? "bar chosen" : "bar");
    const label = document.createElementNS(NS, "text");
    label.setAttribute("x", String(75 + i * 130));
    label.setAttribute("y", "150");
    label.textContent = `${name}: ${d.volume_pct.toFixed(2)} %`;
    const max = document.createElementNS(NS, "text");
    max.setAttribute("x", String(75 + i * 130));
    max.setAttribute("y", "166");
    max.textContent = `max ${d.max_mm.toFixed(2)} mm`;
    svg.append(bar, label, max);
  });
  return svg;
}
