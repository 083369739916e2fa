// Lamina demo part: a turned knob / boss.
//
//   * a flange (Ø76 x 12) with six Ø6 bolt holes on a Ø62 pitch circle,
//   * a waisted neck whose profile is a concave circular arc (Ø45 at both ends, Ø40 at the waist),
//   * a head (Ø60) whose top edge is a convex R6 round (torus) blending tangentially into
//     a shallow spherical dome (R60),
//   * a Ø10 central bore through everything.
//
// Millimetres, axis = z, base on z = 0, top of the dome at z = 32 + 6 + 60 - sqrt(54^2 - 24^2) ≈ 43.63.
// Render (OpenSCAD 2021.01):
//   openscad --export-format binstl -o examples/knob.stl examples/knob.scad
// See examples/README.md for the numbers (triangles, volume, slice loop counts).

$fn = 96;

bore_r    = 5;     // central bore Ø10
flange_r  = 38;    // flange Ø76
flange_h  = 12;
bolt_n    = 6;
bolt_r    = 3;     // bolt holes Ø6
bolt_pcd_r = 31;   // pitch circle Ø62
bolt_fn   = 32;

// Neck: concave arc, circle centred at (neck_cr, neck_cz) of radius neck_rho, outside the material.
neck_z0   = flange_h;            // 12
neck_z1   = 28;
neck_cz   = (neck_z0 + neck_z1) / 2;   // 20
neck_cr   = 34;
neck_rho  = 14;                  // r(z) = 34 - sqrt(14^2 - (z-20)^2): 22.51 at the ends, 20 at z = 20

// Head: cylinder r = 30 from z = 28 to 32, then an R6 round (torus tube centred (24, 32)),
// then a sphere of radius 60 centred on the axis, tangent to the round.
head_r    = 30;
round_rho = 6;
round_cr  = head_r - round_rho;  // 24
round_cz  = 32;
dome_R    = 60;
dome_cz   = round_cz - sqrt((dome_R - round_rho)^2 - round_cr^2);  // ≈ -16.37
blend_a   = atan2(round_cz - dome_cz, round_cr);                   // ≈ 63.6°: where round meets dome

neck_steps  = 24;
round_steps = 16;
dome_steps  = 24;

// Profile in the (r, z) half-plane, counter-clockwise, r >= bore_r.
function neck_pt(i) = let(z = neck_z0 + (neck_z1 - neck_z0) * i / neck_steps)
  [neck_cr - sqrt(neck_rho^2 - (z - neck_cz)^2), z];
function round_pt(i) = let(a = blend_a * i / round_steps)
  [round_cr + round_rho * cos(a), round_cz + round_rho * sin(a)];
// Dome from the blend angle up to where it meets the bore (r = bore_r).
dome_end_a = acos(bore_r / dome_R);
function dome_pt(i) = let(a = blend_a + (dome_end_a - blend_a) * i / dome_steps)
  [dome_R * cos(a), dome_cz + dome_R * sin(a)];

profile = concat(
  [[bore_r, 0], [flange_r, 0], [flange_r, flange_h]],
  [for (i = [0 : neck_steps]) neck_pt(i)],
  [[head_r, neck_z1]],
  [for (i = [0 : round_steps]) round_pt(i)],
  [for (i = [1 : dome_steps]) dome_pt(i)]
);

difference() {
  rotate_extrude(convexity = 4) polygon(profile);
  for (k = [0 : bolt_n - 1])
    rotate([0, 0, 360 * k / bolt_n + 30])
      translate([bolt_pcd_r, 0, -1])
        cylinder(r = bolt_r, h = flange_h + 2, $fn = bolt_fn);
}
