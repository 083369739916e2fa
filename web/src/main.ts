// The console: who is here, the link to laminad, and which view shows. Views: #/machine,
// #/queue, #/job/<id>. The machine's status arrives 5 times a second, a job's on every change.
import { clear, h, notify } from "./dom";
import { JobView } from "./job_view";
import { renderMachine } from "./machine_view";
import { renderQueue } from "./queue_view";
import { Rpc } from "./rpc";
import { currentSession, logout, showLogin } from "./session";
import type { DaemonWarning, Job, MachineStatus, Session } from "./types";

const view = document.getElementById("view")!;
const rpc = new Rpc();
const jobs = new Map<string, Job>();
let machine: MachineStatus | null = null;
let warnings: DaemonWarning[] = [];
let lastWarning = 0;
let session: Session;
let jobView: JobView | null = null;

const can = (role: "operator" | "engineer") =>
  session.role === "engineer" || (role === "operator" && session.role === "operator");

function route(): void {
  const [, name, id] = location.hash.split("/");
  for (const a of Array.from(document.querySelectorAll("nav a"))) a.classList.toggle("active", a.getAttribute("data-view") === name);
  if (name !== "job" || jobView?.jobId !== id) {
    jobView?.dispose();
    jobView = null;
    delete view.dataset.mounted;
  }
  if (name === "job" && id) {
    if (!jobView) {
      jobView = new JobView(view, rpc, id, session.role);
      view.dataset.mounted = "job";
      rpc.call<Job>("job.get", { job: id }).then((j) => { jobs.set(j.id, j); void jobView?.update(j); }).catch((e) => notify(e.message));
    }
  } else if (name === "queue") {
    renderQueue(view, rpc, jobs, can("engineer"), can("engineer"));
  } else {
    view.dataset.mounted = "machine";
    renderMachine(view, machine, warnings);
  }
}

// The daemon's warnings: what is new since the last answer, every few seconds (they are rare;
// the machine's status is what must be live).
const kWarningsEvery_ms = 3000;
async function pollWarnings(): Promise<void> {
  const r = await rpc.call<{ warnings: DaemonWarning[]; last: number }>("server.warnings", { since: lastWarning }).catch(() => null);
  if (r && r.warnings.length) {
    warnings = [...warnings, ...r.warnings].slice(-200);
    lastWarning = r.last;
    if (view.dataset.mounted === "machine") renderMachine(view, machine, warnings);
  }
}

function updateMotionBar(): void {
  const bar = document.getElementById("motion-bar")!;
  const active = machine?.job && ["cutting", "paused"].includes(machine.job_state ?? "");
  bar.hidden = !active;
  for (const b of Array.from(bar.querySelectorAll("button"))) (b as HTMLButtonElement).disabled = !can("operator");
}

function wireMotionBar(): void {
  const press = (method: string) => () => rpc.call(method).then(() => notify(`${method} sent`, "info")).catch((e) => notify(e.message));
  document.getElementById("hold")!.addEventListener("click", press("machine.hold"));
  document.getElementById("resume")!.addEventListener("click", press("machine.resume"));
  document.getElementById("abort")!.addEventListener("click", press("machine.abort"));
}

async function start(): Promise<void> {
  let who = await currentSession();
  if (!who) {
    document.getElementById("top")!.hidden = true;
    await showLogin(view);
    document.getElementById("top")!.hidden = false;
    who = await currentSession();
    if (!who) return void notify("the login did not hold: are cookies allowed?");
  }
  session = who;
  document.getElementById("who")!.textContent = `${session.user} (${session.role})`;
  const out = document.getElementById("logout")!;
  out.hidden = !session.logged_in;
  out.addEventListener("click", async () => { await logout(); location.reload(); });
  wireMotionBar();
  rpc.onLink((up, why) => {
    const pill = document.getElementById("link-state")!;
    pill.textContent = up ? "connected" : `disconnected: ${why}`;
    pill.className = `pill ${up ? "ok" : "bad"}`;
    if (up) void pollWarnings();
    if (up) rpc.call<Job[]>("job.list").then((list) => { for (const j of list) jobs.set(j.id, { ...jobs.get(j.id), ...j } as Job); route(); }).catch(() => undefined);
  });
  rpc.on("notify_machine_status", (status: MachineStatus) => {
    machine = status;
    updateMotionBar();
    if (view.dataset.mounted === "machine") renderMachine(view, machine, warnings);
    jobView?.machine(status);
  });
  rpc.on("notify_job_progress", (job: Job) => {
    jobs.set(job.id, job);
    if (view.dataset.mounted === "queue") renderQueue(view, rpc, jobs, can("engineer"), can("engineer"));
    if (jobView?.jobId === job.id) void jobView.update(job);
  });
  window.addEventListener("hashchange", route);
  if (!location.hash) location.hash = "#/machine";
  route();
  rpc.connect();
  setInterval(() => void pollWarnings(), kWarningsEvery_ms);
}

start().catch((e) => clear(view, h("p", { class: "form-error" }, `The console could not start: ${(e as Error).message}`)));
