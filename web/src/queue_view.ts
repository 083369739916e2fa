// Every job with its state and progress, the upload form with the plan settings, cancel.
import { clear, duration, h, notify } from "./dom";
import type { Rpc } from "./rpc";
import type { Job } from "./types";
import { uploadAndSubmit } from "./upload";

export function progressOf(job: Job): { fraction: number; text: string } {
  if (job.planning) {
    const within = job.planning.total ? (job.planning.done ?? 0) / job.planning.total : 0;
    const fraction = (job.planning.step - 1 + within) / Math.max(1, job.planning.steps);
    return { fraction, text: `${job.planning.phase} (${job.planning.step}/${job.planning.steps})` };
  }
  if (job.progress && job.progress.lines > 0) {
    const f = job.progress.lines_accepted / job.progress.lines;
    const sheet = job.sheets?.find((s) => s.index === job.progress!.sheet);
    const left = job.summary ? job.summary.estimated_cut_s * (1 - f) / Math.max(1, job.summary.sheets) : NaN;
    return { fraction: f, text: `sheet ${job.progress.sheet}: line ${job.progress.lines_accepted} of ${sheet?.lines ?? job.progress.lines}, about ${duration(left)} left` };
  }
  const done = { completed: 1, cancelled: 1, failed: 1 } as Record<string, number>;
  return { fraction: done[job.state] ?? 0, text: job.state.replace("_", " ") };
}

function settingsForm(): { form: HTMLFormElement; read: () => Record<string, unknown> } {
  const field = (name: string, label: string, attrs: Record<string, string> = {}) =>
    h("label", {}, label, " ", h("input", { name, ...attrs }));
  const select = (name: string, label: string, options: string[]) =>
    h("label", {}, label, " ", h("select", { name }, h("option", { value: "" }, "default"), ...options.map((o) => h("option", { value: o }, o))));
  const form = h(
    "form",
    { class: "submit", id: "submit-form" },
    h("h2", {}, "Submit a part"),
    h("label", {}, "Model (STL, OBJ, 3MF, STEP, IGES) ", h("input", { name: "model", type: "file", accept: ".stl,.obj,.3mf,.step,.stp,.iges,.igs", required: true })),
    field("stock", "Stock thicknesses (mm)", { placeholder: "1,2.5,5" }),
    field("stock_file", "or the rack's file on the cell PC", { placeholder: "/srv/lamina/rack.toml" }),
    field("material", "Material", { placeholder: "as the rack says" }),
    field("tolerance_mm", "Tolerance (mm)", { type: "number", step: "0.01", min: "0" }),
    field("tilt_max_deg", "Largest tilt (°)", { type: "number", step: "1", min: "0", max: "89" }),
    select("strategy", "Edge", ["curved", "sloped", "vertical"]),
    select("post", "Post", ["grblhal", "fanuc", "linuxcnc"]),
    field("quality", "Quality (1–5)", { type: "number", step: "1", min: "1", max: "5" }),
    h("button", { type: "submit", class: "big" }, "Upload and plan"),
    h("progress", { max: "1", value: "0", hidden: true }),
  ) as HTMLFormElement;
  const read = () => {
    const settings: Record<string, unknown> = {};
    for (const el of Array.from(form.elements) as HTMLInputElement[]) {
      if (!el.name || el.name === "model" || el.value === "") continue;
      settings[el.name] = el.type === "number" ? Number(el.value) : el.value;
    }
    return settings;
  };
  return { form, read };
}

// The table is redrawn on every update; the form is made once, so typing is never lost.
export function renderQueue(view: HTMLElement, rpc: Rpc, jobs: Map<string, Job>, canSubmit: boolean, canCancel: boolean): void {
  if (view.dataset.mounted !== "queue") mountQueue(view, rpc, jobs, canSubmit);
  const holder = view.querySelector("#queue-table")!;
  const rows = [...jobs.values()].sort((a, b) => a.created_unix_ms - b.created_unix_ms);
  if (!rows.length) return clear(holder, h("p", {}, "No jobs yet."));
  clear(
    holder,
    h(
      "table",
      { class: "queue" },
      h("tr", {}, h("th", {}, "Job"), h("th", {}, "State"), h("th", {}, "Progress"), h("th", {})),
      ...rows.map((job) => jobRow(rpc, job, canCancel)),
    ),
  );
}

function jobRow(rpc: Rpc, job: Job, canCancel: boolean): HTMLElement {
  const p = progressOf(job);
  const terminal = ["completed", "cancelled", "failed"].includes(job.state);
  const cancel = () => rpc.call("job.cancel", { job: job.id }).catch((e) => notify(e.message));
  return h(
    "tr",
    { "data-job": job.id, "data-state": job.state },
    h("td", {}, h("a", { href: `#/job/${job.id}` }, job.name), h("div", { class: "small" }, job.id)),
    h("td", { class: `state ${job.state}` }, job.state.replace("_", " "), job.error ? h("div", { class: "small" }, job.error) : null),
    h("td", {}, h("progress", { max: "1", value: String(p.fraction) }), h("div", { class: "small progress-text" }, p.text)),
    h("td", {}, canCancel && !terminal ? h("button", { onclick: cancel }, "Cancel") : null),
  );
}

function mountQueue(view: HTMLElement, rpc: Rpc, jobs: Map<string, Job>, canSubmit: boolean): void {
  view.dataset.mounted = "queue";
  clear(view, h("h1", {}, "Queue"), h("div", { id: "queue-table" }));
  if (!canSubmit) return;
  const { form, read } = settingsForm();
  form.addEventListener("submit", async (e) => {
    e.preventDefault();
    const file = (form.elements.namedItem("model") as HTMLInputElement).files?.[0];
    if (!file) return;
    const bar = form.querySelector("progress")!;
    bar.hidden = false;
    try {
      const job = await uploadAndSubmit(rpc, file, read(), (f) => (bar.value = f));
      jobs.set(job.id, job);
      location.hash = `#/job/${job.id}`;
    } catch (err) {
      notify(`Not submitted: ${(err as Error).message}`);
    } finally {
      bar.hidden = true;
    }
  });
  view.append(form);
}
