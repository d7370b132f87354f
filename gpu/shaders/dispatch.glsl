// Item indexing for vdbdag compute shaders (see gpu/ComputePipeline.h): the
// workgroup size is specialisation constant 0, and dispatches of more than
// maxComputeWorkGroupCount[0] workgroups use a 2D grid of workgroups. Items
// past the caller's count must be skipped by the shader.
#ifndef VDBDAG_DISPATCH_GLSL
#define VDBDAG_DISPATCH_GLSL

layout(local_size_x_id = 0, local_size_y = 1, local_size_z = 1) in;

uint vdbdagItemIndex() {
    return gl_WorkGroupID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) + gl_GlobalInvocationID.x;
}

#endif
