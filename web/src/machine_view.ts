// The machine and the cell, for a touchscreen at the machine: state, position, feed, program
// line, buffer, link; e-stop, door, pump, pressure, abrasive, jet, PLC — large and coloured.
import { clear, fmt, h } from "./dom";
import type { DaemonWarning, MachineStatus } from "./types";

type Tone = "ok" | "warn" | "bad" | "unknown";

function lamp(label: string, value: string, tone: Tone, id: string): HTMLElement {
  return h("div", { class: `lamp ${tone}`, "data-lamp": id }, h("span", { class: "lamp-label" }, label), h("span", { class: "lamp-value" }, value));
}

function flag(v: boolean | null | undefined, good: string, bad: string, badTone: Tone = "bad"): [string, Tone] {
  if (v === null || v === undefined) return ["unknown", "unknown"];
  return v ? [good, "ok"] : [bad, badTone];
}

// The daemon's warnings, newest first: a PLC that went away, a client refused, a failed login.
function warningList(warnings: DaemonWarning[]): HTMLElement {
  const shown = warnings.slice(-50).reverse();
  return h(
    "section",
    { class: "daemon-warnings" },
    h("h2", {}, "Daemon warnings"),
    shown.length
      ? h("ol", { id: "daemon-warnings", class: "event-log" }, ...shown.map((w) => h("li", { class: w.level === "warning" ? "warn-text" : "form-error" }, `${new Date(w.t_unix_ms).toLocaleTimeString()} ${w.source}: ${w.message}`)))
      : h("p", { id: "daemon-warnings" }, "None since laminad started."),
  );
}

export function renderMachine(view: HTMLElement, s: MachineStatus | null, warnings: DaemonWarning[] = []): void {
  if (!s) return clear(view, h("p", {}, "Waiting for the machine's status…"));
  const p = s.position;
  const c = s.cell;
  const stateTone: Tone = /alarm|fault/i.test(s.state) ? "bad" : /hold|door/i.test(s.state) ? "warn" : "ok";
  const [estop, estopTone] = flag(c?.estop_ok, "released", "PRESSED");
  const [door, doorTone] = flag(c?.door_closed, "closed", "open", "warn");
  const [pump, pumpTone] = flag(c?.pump_ready, "ready", "not ready", "warn");
  const jet: [string, Tone] = c?.jet_is_on === null || c?.jet_is_on === undefined ? ["unknown", "unknown"] : c.jet_is_on ? ["ON", "warn"] : ["off", "ok"];
  const plc: [string, Tone] = !c || c.connected === null ? ["not configured", "unknown"] : c.connected ? [`${fmt(c.read_age_s, 2)} s ago`, "ok"] : ["lost", "bad"];
  clear(
    view,
    h("h1", {}, "Machine"),
    h(
      "section",
      { class: "lamps" },
      lamp("State", s.state_text ? `${s.state} – ${s.state_text}` : s.state, stateTone, "state"),
      lamp("E-stop", estop, estopTone, "estop"),
      lamp("Door", door, doorTone, "door"),
      lamp("Pump", pump, pumpTone, "pump"),
      lamp("Pressure", fmt(c?.pressure_mpa, 0, "MPa"), c?.pressure_mpa ? "ok" : "unknown", "pressure"),
      lamp("Abrasive", fmt(c?.abrasive_g_per_min, 0, "g/min"), c?.abrasive_g_per_min ? "ok" : "unknown", "abrasive"),
      lamp("Jet", jet[0], jet[1], "jet"),
      lamp("PLC", plc[0], plc[1], "plc"),
      c?.fault ? lamp("Fault", c.fault, "bad", "fault") : null,
      s.store && !s.store.ok ? lamp("Job store", s.store.error ?? "failed", "bad", "store") : null,
    ),
    h(
      "section",
      { class: "dro" },
      ...(["x_mm", "y_mm", "z_mm", "a_deg", "c_deg"] as const).map((axis) =>
        h("div", { class: "axis" }, h("span", {}, axis[0].toUpperCase()), h("b", {}, fmt(p?.[axis], axis.endsWith("deg") ? 2 : 3))),
      ),
    ),
    h(
      "table",
      { class: "facts" },
      h("tr", {}, h("th", {}, "Feed"), h("td", {}, fmt(s.feed_mm_per_s === undefined ? undefined : s.feed_mm_per_s * 60, 0, "mm/min"))),
      h("tr", {}, h("th", {}, "Job"), h("td", {}, s.job ? `${s.job} (${s.job_state}), sheet ${s.sheet}` : "none")),
      h("tr", {}, h("th", {}, "Program line"), h("td", {}, s.program_line ?? s.line ?? "–")),
      h("tr", {}, h("th", {}, "Lines sent / accepted"), h("td", {}, `${s.lines_sent ?? "–"} / ${s.lines_accepted ?? "–"}`)),
      h("tr", {}, h("th", {}, "Planner blocks free"), h("td", {}, s.planner_blocks_free ?? "–")),
      h("tr", {}, h("th", {}, "Link"), h("td", {}, s.link ?? "–")),
    ),
    warningList(warnings),
  );
}
