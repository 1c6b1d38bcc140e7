// The flat-shading interface: what glsl/geometry.glsl hands glsl/fragment.glsl, one value per
// triangle (flat) but the world position and the UV, declared here once for both ends. The
// including stage says which end it is: #define FLAT_VARYING out (geometry.glsl) or in
// (fragment.glsl). Without SHADOW_MAPS, the colours lit for each side; with it, the lighting's
// terms apart (lighting.glsl's keep_light_terms, handed on by hand_on_light_terms), the face
// normal and the interpolated world position, for fragment.glsl to weigh each light's term by
// its visibility. TEXTURED: the UV, interpolated, and the lighting of the coefficients the
// texel modulates beside the others'. The twin's names: reference/geometry.py, TriangleOutputs.

#ifdef TEXTURED
FLAT_VARYING vec2 f_uv;
#endif
#ifdef SHADOW_MAPS
FLAT_VARYING vec3 f_world_position;               // where fragment.glsl looks the maps up
flat FLAT_VARYING vec3 f_face_normal;
flat FLAT_VARYING vec3 f_ambient;                 // I_a k_a
#ifdef TEXTURED
flat FLAT_VARYING vec3 f_modulated_ambient;       // I_a k_a where the texel modulates k_a, else 0
#endif
#if NUM_DIRECTIONAL_TERMS > 0
flat FLAT_VARYING vec3 f_directional_terms_front[NUM_DIRECTIONAL_TERMS];
#ifdef TWO_SIDED
flat FLAT_VARYING vec3 f_directional_terms_back[NUM_DIRECTIONAL_TERMS];
#endif
#endif
#if NUM_POINT_TERMS > 0
flat FLAT_VARYING vec3 f_point_terms_front[NUM_POINT_TERMS];
#ifdef TWO_SIDED
flat FLAT_VARYING vec3 f_point_terms_back[NUM_POINT_TERMS];
#endif
#endif
#else
flat FLAT_VARYING vec3 f_color_front;             // lit with N (TEXTURED: the others' terms)
#ifdef TWO_SIDED
flat FLAT_VARYING vec3 f_color_back;              // lit with -N
#endif
#ifdef TEXTURED
flat FLAT_VARYING vec3 f_modulated_front;         // the modulated coefficients' terms, lit with N
#ifdef TWO_SIDED
flat FLAT_VARYING vec3 f_modulated_back;
#endif
#endif
#endif
