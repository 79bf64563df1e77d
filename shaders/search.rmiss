#version 460
// Miss shader of the rt-pipeline search: nothing to do.
#extension GL_EXT_ray_tracing : require
layout(location = 0) rayPayloadInEXT uint p_unused;
void main() {}
