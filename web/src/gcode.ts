// A sheet's program (sheet-<n>.nc) read back into moves of the tool tip, for the 3D toolpath.
// It reads what every post of ours writes (docs/posts.md): modal G0/G1, X Y Z A C, G20/G21,
// comments in parentheses or after ';', line numbers, M2/M30 as the end. Arcs are not ours to
// write; a G2/G3 is counted and drawn as its chord, so the view never pretends to more.
import { type Head, toolAxis, toolTip, type Vec3 } from "./kinematics";

export interface TipMove {
  rapid: boolean;
  tip: Vec3; // where the move ends, mm in the sheet's frame
  axis: Vec3; // tool axis there (unit, tip → nozzle)
  tilted: boolean; // A away from 0: the jet leans, the move is a 5-axis one
}

export interface ParsedProgram {
  moves: TipMove[];
  arcs: number;
}

const kWord = /([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))/g;
const kTiltedBelowDeg = 1e-3;

function stripComments(line: string): string {
  return line.replace(/\([^)]*\)/g, "").replace(/;.*$/, "").toUpperCase();
}

export function parseProgram(text: string, head: Head): ParsedProgram {
  const pos = { X: 0, Y: 0, Z: 0, A: 0, C: 0 };
  let motion: number | null = null;
  let scale = 1; // mm per program unit
  const moves: TipMove[] = [];
  let arcs = 0;
  for (const raw of text.split("\n")) {
    const line = stripComments(raw);
    let moved = false;
    let end = false;
    for (const [, letter, value] of line.matchAll(kWord)) {
      const v = Number(value);
      if (letter === "G") {
        if (v === 0 || v === 1 || v === 2 || v === 3) motion = v;
        else if (v === 20) scale = 25.4;
        else if (v === 21) scale = 1;
      } else if (letter === "M" && (v === 2 || v === 30)) {
        end = true;
      } else if (letter === "X" || letter === "Y" || letter === "Z") {
        pos[letter] = v * scale;
        moved = true;
      } else if (letter === "A" || letter === "C") {
        pos[letter] = v;
        moved = true;
      }
    }
    if (moved && motion !== null) {
      if (motion >= 2) ++arcs;
      const axis = toolAxis(pos.A, pos.C, head);
      moves.push({ rapid: motion === 0, tip: toolTip(pos.X, pos.Y, pos.Z, axis, head), axis, tilted: Math.abs(pos.A) > kTiltedBelowDeg });
    }
    if (end) break;
  }
  return { moves, arcs };
}
