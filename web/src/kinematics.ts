// The AC tilting head, as core/include/lamina/core/kinematics.hpp has it: a program's X Y Z A C
// into the tool tip and the tool axis (unit, tip → nozzle). With θ = c_sign·C + c_offset and
// α = a_sign·A, axis = Rz(θ)·Rx(α)·ẑ = (sin θ sin α, −cos θ sin α, cos α). Without RTCP the
// program carries the pivot, shifted so that at A = 0 it equals the tip:
// xyz = tip + pivot·(axis − ẑ).

// report.json's cam.head (degrees, as the program's A and C), and cam.rtcp.
export interface Head {
  pivot_mm: number;
  a_sign: number;
  c_sign: number;
  c_offset_deg: number;
  rtcp: boolean;
}

export type Vec3 = [number, number, number];

const kRad = Math.PI / 180;

export function toolAxis(a_deg: number, c_deg: number, head: Head): Vec3 {
  const alpha = head.a_sign * a_deg * kRad;
  const theta = (head.c_sign * c_deg + head.c_offset_deg) * kRad;
  const s = Math.sin(alpha);
  return [Math.sin(theta) * s, -Math.cos(theta) * s, Math.cos(alpha)];
}

// The tool tip of machine coordinates (mm, degrees).
export function toolTip(x_mm: number, y_mm: number, z_mm: number, axis: Vec3, head: Head): Vec3 {
  if (head.rtcp) return [x_mm, y_mm, z_mm];
  return [x_mm - head.pivot_mm * axis[0], y_mm - head.pivot_mm * axis[1], z_mm - head.pivot_mm * (axis[2] - 1)];
}
