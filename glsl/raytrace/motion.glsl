// Twin: reference/raytrace/motion.py
// Motion blur's rule (docs/conventions.md, "Motion blur"; the data: renderer/core/motion.py):
// an object moving with velocity v and angular velocity w (unit axis k, rate |w| radians per
// unit time, about the axis through its centre c) has at time t each point X at
//   X(t) = X + (R(t |w|) - I)(X - c) + t v,   (R(a) - I) x = sin(a) k x x + (1 - cos a) k x (k x x)
// (Rodrigues), in this displacement form so that t = 0 is exact: sin(0) = 0, 1 - cos(0) = 0 and
// 0 v make every term 0, and X + 0 is X bit for bit. The inverse (into the object's time-0
// frame) is Y - t v + (R(-t |w|) - I)(Y - t v - c): the same terms with sin negated. A camera
// sample's time is open + u (close - open).

// One object's motion at one time (motion_at): c, t v, the unit axis (or 0), sin and 1 - cos of
// the angle t |w|.
struct Motion {
    vec3 centre;
    vec3 shift;
    vec3 axis;
    float sine;
    float versine;
};

// The time of a camera sample whose TIME number is u, in the shutter (open, close).
float motion_time(vec2 shutter, float u) {
    return shutter.x + u * (shutter.y - shutter.x);
}

// The motion at time t of an object whose rows are (c, rate), (v, 0), (axis, 0)
// (renderer/core/motion.py, SceneMotion.rows).
Motion motion_at(vec4 row0, vec4 row1, vec4 row2, float t) {
    float angle = t * row0.w;
    return Motion(row0.xyz, t * row1.xyz, row2.xyz, sin(angle), 1.0 - cos(angle));
}

// (R - I) x for the rotation whose sine is `sine` (m.sine forwards, -m.sine backwards).
vec3 motion_turn(Motion m, float sine, vec3 x) {
    vec3 kx = cross(m.axis, x);
    return sine * kx + m.versine * cross(m.axis, kx);
}

// A point of the object at time 0 where it is at the motion's time.
vec3 motion_point(Motion m, vec3 X) {
    return X + motion_turn(m, m.sine, X - m.centre) + m.shift;
}

// A point at the motion's time where it was at time 0 (the inverse of motion_point).
vec3 motion_point_back(Motion m, vec3 Y) {
    vec3 Y0 = Y - m.shift;
    return Y0 + motion_turn(m, -m.sine, Y0 - m.centre);
}

// A direction (a normal) of the object turned with it, and back.
vec3 motion_direction(Motion m, vec3 D) {
    return D + motion_turn(m, m.sine, D);
}

vec3 motion_direction_back(Motion m, vec3 D) {
    return D + motion_turn(m, -m.sine, D);
}

// The plane P.N + d = 0 of the object at the motion's time: N_t = R N and
// d_t = d - N_t.(t v) - ((R - I) N).c, which is d where t = 0.
void motion_plane(Motion m, vec3 N, float d, out vec3 N_t, out float d_t) {
    vec3 turned = motion_turn(m, m.sine, N);
    N_t = N + turned;
    d_t = d - dot(N_t, m.shift) - dot(turned, m.centre);
}
