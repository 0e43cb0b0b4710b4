// A two-body knuckle joint with two spiral torsion springs, for benchmarks/cli.py to time OpenSCAD on
// a module comparable to `rjcad joint` (written for this benchmark; rjcad does not use it).
// Springs: the default spring's size (rjcad spring's default design: strip 9 x 0.8 mm, about 165 mm long,
// outer radius 9.17 mm), one on each side of the knuckle (the paper's stacked layout), inner end on the
// ground body's pin, outer end in a key on the moving body. Tendon channels through both links.
// Units: mm. Render: openscad -o knuckle.stl knuckle.scad

b = 9.0;          // spring width (along the axis)
t = 0.8;          // strip thickness
r_in = 3.6;       // inner radius of the spiral
r_out = 9.17;     // outer radius
len_target = 165; // strip length
clear = 0.4;      // clearance between the bodies
pin_r = 2.0;      // knuckle pin radius
link = 40;        // axis to link end
wid = 20;         // link width (Y)
eye_h = 10;       // height of the knuckle eye
tendon_d = 1.0;   // tendon channel diameter
arm = 6;          // tendon moment arm
$fn = 64;

turns = len_target / (PI * (r_in + r_out));   // Archimedean length ~ pi (r_in + r_out) N
pitch = (r_out - r_in) / turns;
step = 6;  // degrees per point: 0.105 rad, as rjcad's tessellation (0.1 rad angular deflection; $fn = 64 likewise)
z1 = b + clear;                                // eye band from z1 to z2
z2 = z1 + eye_h;
H = z2 + clear + b;                            // total height

function spiral(r0, off) = [for (a = [0 : step : 360 * turns])
    let (r = r0 + pitch * a / 360 + off) [r * cos(a), r * sin(a)]];

module strip() {  // the spiral strip, thickness t, from r_in to r_out
    outer = spiral(r_in, t / 2);
    inner = spiral(r_in, -t / 2);
    linear_extrude(height = b) polygon(concat(outer, [for (i = [len(inner) - 1 : -1 : 0]) inner[i]]));
}

module spring_at(z) {
    translate([0, 0, z]) {
        strip();
        cylinder(r = r_in - t / 2 + 0.01, h = b);                        // hub on the pin
    }
}

module channel(x0, x1, z) {
    translate([x0, arm, z]) rotate([0, 90, 0]) cylinder(d = tendon_d, h = x1 - x0, $fn = 24);
}

module ground() {
    difference() {
        union() {
            translate([-link, -wid / 2, 0]) cube([link - r_out - 2 - clear, wid, H]);
            spring_at(0);
            spring_at(z2 + clear);
            cylinder(r = pin_r, h = H);                                  // the pin through the stack
            translate([-r_out - 2.5, -wid / 2, 0]) cube([1.5, wid, H]);  // spine joining the hubs' block
        }
        channel(-link - 1, -r_out, (z1 + z2) / 2);
    }
}

module moving() {
    difference() {
        union() {
            translate([r_out + 2 + clear, -wid / 2, 0]) cube([link - r_out - 2 - clear, wid, H]);
            translate([0, 0, z1]) difference() {                         // the eye around the pin
                cylinder(r = arm, h = eye_h);
                translate([0, 0, -1]) cylinder(r = pin_r + clear, h = eye_h + 2);
            }
            translate([0, -3, z1]) cube([r_out + 3 + clear, 6, eye_h]); // eye to link
            for (z = [0, z2 + clear])                                    // keys holding the springs' outer ends
                translate([r_out - 0.5, -1.5, z]) cube([3 + clear, 3, b]);
        }
        channel(r_out, link + 1, (z1 + z2) / 2);
        translate([0, 0, (z1 + z2) / 2 - tendon_d / 2]) difference() {  // tendon groove around the eye
            cylinder(r = arm + 1, h = tendon_d);
            translate([0, 0, -1]) cylinder(r = arm - tendon_d / 2, h = tendon_d + 2);
        }
    }
}

ground();
moving();
