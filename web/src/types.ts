// What laminad sends (docs/api.md): the machine's status and the job object.

export interface Position {
  x_mm: number;
  y_mm: number;
  z_mm: number;
  a_deg: number;
  c_deg: number;
}

export interface Cell {
  connected: boolean | null;
  read_age_s: number | null;
  estop_ok: boolean | null;
  door_closed: boolean | null;
  pump_ready: boolean | null;
  jet_is_on: boolean | null;
  pressure_mpa: number | null;
  abrasive_g_per_min: number | null;
  alarm_latched: boolean | null;
  alarm_code: number | null;
  fault?: string;
}

export interface MachineStatus {
  state: string;
  state_text?: string;
  position?: Position;
  feed_mm_per_s?: number;
  line?: number;
  planner_blocks_free?: number;
  lines_sent?: number;
  lines_accepted?: number;
  link?: string;
  job: string | null;
  job_state?: string;
  sheet?: number;
  program_line?: number;
  cell?: Cell;
  store?: { ok: boolean; error: string | null };
}

export interface Sheet {
  index: number;
  program: string;
  svg: string;
  material: string;
  thickness_mm: number;
  lines: number;
  state: string;
  last_acked_line: number;
  resume_line: number;
  contour: number;
  cut_seconds: number;
}

export interface Job {
  id: string;
  state: string;
  name: string;
  error: string;
  current_sheet: number;
  sheets: Sheet[];
  summary?: {
    layers: number;
    sheets: number;
    lines: number;
    estimated_cut_s: number;
    deviation: Record<string, { volume_pct: number; max_mm: number }>;
    warnings: string[];
  };
  planning?: { phase: string; step: number; steps: number; done?: number; total?: number };
  progress?: { sheet: number; lines_accepted: number; lines: number };
  created_unix_ms: number;
}

export interface JobEvent {
  t_unix_ms: number;
  kind: string;
  data: Record<string, unknown>;
}

export interface Session {
  user: string;
  role: "viewer" | "operator" | "engineer";
  logged_in: boolean;
  users_configured: boolean;
}

// server.warnings: what laminad warned about, oldest first.
export interface DaemonWarning {
  seq: number;
  t_unix_ms: number;
  level: "warning" | "error" | "critical";
  source: string;
  message: string;
}
