#!/usr/bin/env python3
"""homcull.h from Python's ctypes: the C interface is FFI-friendly.

Usage: test_ctypes.py <path to libhomcull.so> <path to homcull.h>

Mirrors the header's structs with ctypes.Structure and checks their sizes against the header's
HOMCULL_CHECK_SIZE_ lines, checks the version against the header's macros, then runs a small
frame through a context whose memory comes from a Python allocator: a wall at z = -10, a box
behind it (occluded), one in front of it (visible), one behind the camera (view-culled). Errors
must come back as results with messages. Standard library only. Exits 0 on success.
"""
import ctypes
import math
import os
import re
import struct
import sys
from ctypes import (CFUNCTYPE, POINTER, Structure, c_char_p, c_double, c_float, c_int32, c_size_t,
                    c_uint8, c_uint16, c_uint32, c_uint64, c_void_p)


class TestFailure(Exception):
    pass


def check(condition, message):
    if not condition:
        raise TestFailure(message)


# ---- homcull.h, mirrored -------------------------------------------------------------------------

homcull_result = c_int32
homcull_isa = c_int32
homcull_matrix_layout = c_int32
homcull_depth_range = c_int32
homcull_winding = c_int32
homcull_cull = c_int32
homcull_visibility = c_uint8

HOMCULL_OK = 0
HOMCULL_ERROR_INVALID_ARGUMENT = 1
HOMCULL_ISA_BEST = 0
HOMCULL_ISA_COUNT = 9
HOMCULL_COLUMN_MAJOR = 0
HOMCULL_DEPTH_MINUS_ONE_TO_ONE = 0
HOMCULL_FRONT_CCW = 0
HOMCULL_CULL_BACK = 0
HOMCULL_VISIBLE = 0
HOMCULL_OCCLUDED = 1
HOMCULL_VIEW_CULLED = 2

# Callbacks. allocate's void* return: a Python int (an address) or None (null).
allocate_fn = CFUNCTYPE(c_void_p, c_void_p, c_size_t, c_size_t)
deallocate_fn = CFUNCTYPE(None, c_void_p, c_void_p, c_size_t)
homcull_error_callback = CFUNCTYPE(None, c_void_p, homcull_result, c_char_p)


class homcull_allocator(Structure):
    _fields_ = [("allocate", allocate_fn), ("deallocate", deallocate_fn), ("user", c_void_p)]


class homcull_context_desc(Structure):
    _fields_ = [("allocator", homcull_allocator), ("on_error", homcull_error_callback), ("error_user", c_void_p),
                ("isa", homcull_isa), ("reserved", c_uint32)]


class homcull_mesh_desc(Structure):
    _fields_ = [("positions", POINTER(c_float)), ("position_stride", c_size_t), ("vertex_count", c_size_t),
                ("indices", c_void_p), ("index_size", c_uint32), ("reserved", c_uint32), ("triangle_count", c_size_t)]


class homcull_view(Structure):
    _fields_ = [("world_to_clip", c_double * 16), ("layout", homcull_matrix_layout), ("depth_range", homcull_depth_range),
                ("front_face", homcull_winding), ("cull", homcull_cull), ("flags", c_uint32), ("reserved", c_uint32)]


class homcull_buffer_desc(Structure):
    _fields_ = [("width", c_int32), ("height", c_int32), ("samples", c_int32), ("near_distance", c_float),
                ("flags", c_uint32), ("reserved", c_uint32)]


class homcull_reserve_desc(Structure):
    _fields_ = [("max_width", c_int32), ("max_height", c_int32), ("max_draw_triangles", c_size_t),
                ("max_draw_vertices", c_size_t), ("max_task_list_draws", c_size_t), ("max_task_list_triangles", c_size_t),
                ("max_job_threads", c_uint32), ("reserved", c_uint32)]


job_task_fn = CFUNCTYPE(None, c_void_p, c_size_t)
job_run_fn = CFUNCTYPE(None, c_void_p, c_size_t, job_task_fn, c_void_p)


class homcull_job_system(Structure):
    _fields_ = [("run", job_run_fn), ("user", c_void_p), ("threads", c_uint32), ("reserved", c_uint32)]


class homcull_triangles(Structure):
    _fields_ = [("positions", POINTER(c_float)), ("position_stride", c_size_t), ("vertex_count", c_size_t),
                ("indices", c_void_p), ("index_size", c_uint32), ("reserved", c_uint32), ("triangle_count", c_size_t)]


class homcull_box(Structure):
    _fields_ = [("min", c_float * 3), ("max", c_float * 3)]


class homcull_rect(Structure):
    _fields_ = [("min_x", c_float), ("min_y", c_float), ("max_x", c_float), ("max_y", c_float), ("nearest_w", c_float)]


class homcull_frame_stats(Structure):
    _fields_ = [("triangles_in", c_uint64), ("triangles_drawn", c_uint64), ("triangles_skipped", c_uint64),
                ("clusters_hidden", c_uint64), ("draw_calls", c_uint64), ("allocations", c_uint64)]


# Opaque handles, each its own pointer type so that a mesh cannot be passed for a buffer.
class homcull_sorter_desc(Structure):
    _fields_ = [("object_meshes", c_void_p), ("object_count", c_size_t)]


class homcull_sort_frame(Structure):
    _fields_ = [("model_matrices", POINTER(c_float)), ("layout", homcull_matrix_layout), ("eye", c_float * 3),
                ("planes", POINTER(c_float)), ("plane_count", c_uint32), ("from_scratch", c_uint32)]


class homcull_sort_layer(Structure):
    _fields_ = [("first", c_uint32), ("count", c_uint32)]


class homcull_occlusion_pair(Structure):
    _fields_ = [("occluder", c_uint32), ("occluded", c_uint32)]


class homcull_sort_result(Structure):
    _fields_ = [("order", POINTER(c_uint32)), ("order_count", c_size_t), ("layers", POINTER(homcull_sort_layer)),
                ("layer_count", c_size_t), ("pairs", POINTER(homcull_occlusion_pair)), ("pair_count", c_size_t),
                ("cycles", c_uint32), ("objects_in_cycles", c_uint32)]


class homcull_context(Structure):
    pass


class homcull_mesh(Structure):
    pass


class homcull_buffer(Structure):
    pass


class homcull_sorter(Structure):
    pass


context_p = POINTER(homcull_context)
mesh_p = POINTER(homcull_mesh)
buffer_p = POINTER(homcull_buffer)
sorter_p = POINTER(homcull_sorter)

# The name in each HOMCULL_CHECK_SIZE_(name, ...) line and the ctypes type it checks.
MIRRORS = {
    "box": homcull_box, "rect": homcull_rect, "view": homcull_view, "buffer_desc": homcull_buffer_desc,
    "frame_stats": homcull_frame_stats, "allocator": homcull_allocator, "context_desc": homcull_context_desc,
    "mesh_desc": homcull_mesh_desc, "triangles": homcull_triangles, "reserve_desc": homcull_reserve_desc,
    "job_system": homcull_job_system, "sorter_desc": homcull_sorter_desc, "sort_frame": homcull_sort_frame,
    "sort_layer": homcull_sort_layer, "occlusion_pair": homcull_occlusion_pair, "sort_result": homcull_sort_result,
}


def bind(lib):
    """argtypes and restype of every function the test calls."""
    def f(name, restype, *argtypes):
        fn = getattr(lib, name)
        fn.restype = restype
        fn.argtypes = list(argtypes)
    f("homcull_result_name", c_char_p, homcull_result)
    f("homcull_last_error", c_char_p)
    f("homcull_version", c_uint32)
    f("homcull_supported_isas", c_uint32)
    f("homcull_isa_name", c_char_p, homcull_isa)
    f("homcull_context_create", homcull_result, POINTER(homcull_context_desc), POINTER(context_p))
    f("homcull_context_destroy", None, context_p)
    f("homcull_context_isa", homcull_isa, context_p)
    f("homcull_context_allocated_bytes", c_uint64, context_p)
    f("homcull_mesh_create", homcull_result, context_p, POINTER(homcull_mesh_desc), POINTER(mesh_p))
    f("homcull_mesh_destroy", None, mesh_p)
    f("homcull_mesh_triangle_count", c_size_t, mesh_p)
    f("homcull_buffer_create", homcull_result, context_p, POINTER(homcull_buffer_desc), POINTER(buffer_p))
    f("homcull_buffer_destroy", None, buffer_p)
    f("homcull_buffer_allocated_bytes", c_uint64, buffer_p)
    f("homcull_buffer_begin_frame", homcull_result, buffer_p, POINTER(homcull_view))
    f("homcull_buffer_draw_mesh", homcull_result, buffer_p, mesh_p, POINTER(c_float), c_size_t)
    f("homcull_buffer_test_boxes", homcull_result, buffer_p, POINTER(homcull_box), c_size_t, POINTER(c_float),
      POINTER(homcull_visibility))
    f("homcull_buffer_frame_stats", homcull_result, buffer_p, POINTER(homcull_frame_stats))
    f("homcull_buffer_begin_tasks", homcull_result, buffer_p)
    f("homcull_buffer_close_tasks", homcull_result, buffer_p, POINTER(c_size_t))
    f("homcull_buffer_run_task", homcull_result, buffer_p, c_size_t)
    f("homcull_buffer_finish_tasks", homcull_result, buffer_p)
    f("homcull_sorter_create", homcull_result, context_p, POINTER(homcull_sorter_desc), POINTER(sorter_p))
    f("homcull_sorter_destroy", None, sorter_p)
    f("homcull_sorter_sort", homcull_result, sorter_p, POINTER(homcull_sort_frame), POINTER(homcull_sort_result))


# ---- The checks -------------------------------------------------------------------------------------

def check_sizes(header_text):
    """Every HOMCULL_CHECK_SIZE_ line of the header against ctypes.sizeof of its mirror."""
    pointer_size, size_t_size = struct.calcsize("P"), struct.calcsize("N")
    check(ctypes.sizeof(c_void_p) == pointer_size and ctypes.sizeof(c_size_t) == size_t_size,
          "ctypes and struct disagree on the pointer or size_t size")
    checks = re.findall(r"^HOMCULL_CHECK_SIZE_\(\s*(\w+)\s*,\s*(\w+)\s*,\s*(.+?)\);\s*$", header_text, re.MULTILINE)
    check(checks, "no HOMCULL_CHECK_SIZE_ lines found in the header")
    names = set()
    for name, ctype_name, expression in checks:
        names.add(name)
        check(name in MIRRORS, f"the header checks the size of {ctype_name}, which this test does not mirror")
        mirror = MIRRORS[name]
        check(mirror.__name__ == ctype_name, f"size check '{name}' is of {ctype_name}, mirrored as {mirror.__name__}")
        arithmetic = expression.replace("sizeof(void*)", str(pointer_size)).replace("sizeof(size_t)", str(size_t_size))
        check(re.fullmatch(r"[0-9+*() ]+", arithmetic), f"cannot evaluate the size of {ctype_name}: {expression}")
        expected = eval(arithmetic, {"__builtins__": {}})  # digits, +, *, parentheses only
        check(ctypes.sizeof(mirror) == expected,
              f"sizeof({ctype_name}): ctypes gives {ctypes.sizeof(mirror)}, the header asserts {expression} = {expected}")
    check(names == set(MIRRORS), f"mirrored structs the header does not check: {sorted(set(MIRRORS) - names)}")
    # A few offsets the sizes alone would not catch.
    check(homcull_context_desc.isa.offset == 5 * pointer_size, "homcull_context_desc.isa is misplaced")
    check(homcull_mesh_desc.triangle_count.offset == 4 * pointer_size + 8, "homcull_mesh_desc.triangle_count is misplaced")
    check(homcull_view.layout.offset == 128, "homcull_view.layout is misplaced")
    return len(checks)


def header_version(header_text):
    parts = {}
    for part in ("MAJOR", "MINOR", "PATCH"):
        match = re.search(rf"^#define HOMCULL_VERSION_{part} (\d+)\s*$", header_text, re.MULTILINE)
        check(match, f"HOMCULL_VERSION_{part} not found in the header")
        parts[part] = int(match.group(1))
    return parts["MAJOR"] * 10000 + parts["MINOR"] * 100 + parts["PATCH"], parts


class PythonAllocator:
    """The engine's memory from Python: libc's aligned_alloc and free, with counts."""

    def __init__(self):
        libc = ctypes.CDLL(None)
        self.aligned_alloc = libc.aligned_alloc
        self.aligned_alloc.restype, self.aligned_alloc.argtypes = c_void_p, [c_size_t, c_size_t]
        self.free = libc.free
        self.free.restype, self.free.argtypes = None, [c_void_p]
        self.user = ctypes.c_int(12345)  # its address is the user pointer the callbacks must get back
        self.calls = self.frees = 0
        self.live = {}  # address: size
        self.problems = []  # raised in a callback, where an exception cannot propagate
        # The callback objects: kept alive as long as this allocator (and so the context) is.
        self.allocate_cb = allocate_fn(self._allocate)
        self.deallocate_cb = deallocate_fn(self._deallocate)

    def user_pointer(self):
        return ctypes.addressof(self.user)

    def _allocate(self, user, size, alignment):
        self.calls += 1
        if user != self.user_pointer():
            self.problems.append(f"allocate got user {user!r}, not {self.user_pointer():#x}")
        if alignment == 0 or alignment & (alignment - 1) or alignment > 64:
            self.problems.append(f"allocate asked for alignment {alignment}, not a power of two up to 64")
            return None
        memory = self.aligned_alloc(alignment, (size + alignment - 1) // alignment * alignment)
        if memory:
            self.live[memory] = size
        return memory

    def _deallocate(self, user, memory, size):
        self.frees += 1
        if user != self.user_pointer():
            self.problems.append(f"deallocate got user {user!r}")
        if memory not in self.live:
            self.problems.append(f"deallocate of {memory!r}, which allocate did not return (or was freed)")
            return
        if size != self.live[memory]:
            self.problems.append(f"deallocate of {memory!r} with size {size}, allocated with {self.live[memory]}")
        del self.live[memory]
        self.free(memory)

    def struct(self):
        return homcull_allocator(self.allocate_cb, self.deallocate_cb, self.user_pointer())


class ErrorLog:
    def __init__(self):
        self.user = ctypes.c_int(678)
        self.messages = []  # (result, message bytes)
        self.problems = []
        self.callback = homcull_error_callback(self._on_error)

    def _on_error(self, user, result, message):
        if user != ctypes.addressof(self.user):
            self.problems.append(f"the error callback got user {user!r}")
        self.messages.append((result, message))  # c_char_p arrives as bytes (copied)


def gl_perspective(fov_y, aspect, near, far):
    """glm::perspectiveRH_NO, column-major: element (r, c) at [4c + r]."""
    f = 1.0 / math.tan(fov_y / 2)
    m = [0.0] * 16
    m[4 * 0 + 0] = f / aspect
    m[4 * 1 + 1] = f
    m[4 * 2 + 2] = -(far + near) / (far - near)
    m[4 * 2 + 3] = -1.0  # row 3, column 2: clip w = -z
    m[4 * 3 + 2] = -2.0 * far * near / (far - near)
    return m


def run(lib_path, header_path):
    with open(header_path, encoding="utf-8") as f:
        header_text = f.read()
    size_checks = check_sizes(header_text)

    lib = ctypes.CDLL(os.path.abspath(lib_path))
    bind(lib)

    version, parts = header_version(header_text)
    linked = lib.homcull_version()
    check(linked == version, f"homcull_version() is {linked}, the header's HOMCULL_VERSION is {version}")

    isas = lib.homcull_supported_isas()
    check(isas & (1 << 1), "homcull_supported_isas() lacks SCALAR")
    check(lib.homcull_result_name(HOMCULL_ERROR_INVALID_ARGUMENT) == b"HOMCULL_ERROR_INVALID_ARGUMENT",
          "homcull_result_name(1) is wrong")

    memory, errors = PythonAllocator(), ErrorLog()
    desc = homcull_context_desc(memory.struct(), errors.callback, ctypes.addressof(errors.user), HOMCULL_ISA_BEST, 0)
    context = context_p()
    r = lib.homcull_context_create(ctypes.byref(desc), ctypes.byref(context))
    check(r == HOMCULL_OK, f"homcull_context_create: {r} {lib.homcull_last_error()!r}")
    check(bool(context), "homcull_context_create returned OK but no context")
    check(memory.calls >= 1, "the context did not come from the Python allocator")
    isa = lib.homcull_context_isa(context)
    check(0 < isa < HOMCULL_ISA_COUNT and isas & (1 << isa), f"homcull_context_isa() is {isa}")

    # The wall: z = -10, x and y in [-20, 20], two triangles counter-clockwise seen from the origin.
    positions = (c_float * 12)(-20, -20, -10,  20, -20, -10,  20, 20, -10,  -20, 20, -10)
    indices = (c_uint16 * 6)(0, 1, 2, 0, 2, 3)
    mesh_desc = homcull_mesh_desc(positions=ctypes.cast(positions, POINTER(c_float)), position_stride=12,
                                  vertex_count=4, indices=ctypes.cast(indices, c_void_p), index_size=2,
                                  reserved=0, triangle_count=2)
    mesh = mesh_p()
    r = lib.homcull_mesh_create(context, ctypes.byref(mesh_desc), ctypes.byref(mesh))
    check(r == HOMCULL_OK, f"homcull_mesh_create: {r} {lib.homcull_last_error()!r}")
    check(lib.homcull_mesh_triangle_count(mesh) == 2, "homcull_mesh_triangle_count is not 2")

    buffer_desc = homcull_buffer_desc(width=160, height=90, samples=1, near_distance=0.1, flags=0, reserved=0)
    buffer = buffer_p()
    r = lib.homcull_buffer_create(context, ctypes.byref(buffer_desc), ctypes.byref(buffer))
    check(r == HOMCULL_OK, f"homcull_buffer_create: {r} {lib.homcull_last_error()!r}")

    view = homcull_view()
    view.world_to_clip[:] = gl_perspective(math.radians(60.0), 16.0 / 9.0, 0.1, 100.0)  # the view matrix is the identity
    view.layout, view.depth_range = HOMCULL_COLUMN_MAJOR, HOMCULL_DEPTH_MINUS_ONE_TO_ONE
    view.front_face, view.cull = HOMCULL_FRONT_CCW, HOMCULL_CULL_BACK
    r = lib.homcull_buffer_begin_frame(buffer, ctypes.byref(view))
    check(r == HOMCULL_OK, f"homcull_buffer_begin_frame: {r} {lib.homcull_last_error()!r}")
    r = lib.homcull_buffer_draw_mesh(buffer, mesh, None, 1)
    check(r == HOMCULL_OK, f"homcull_buffer_draw_mesh: {r} {lib.homcull_last_error()!r}")

    boxes = (homcull_box * 3)(
        homcull_box((-1, -1, -30), (1, 1, -28)),  # behind the wall
        homcull_box((-1, -1, -8), (1, 1, -6)),    # in front of it
        homcull_box((-1, -1, 5), (1, 1, 7)),      # behind the camera
    )
    expected = [HOMCULL_OCCLUDED, HOMCULL_VISIBLE, HOMCULL_VIEW_CULLED]
    visibility = (homcull_visibility * 3)(255, 255, 255)
    r = lib.homcull_buffer_test_boxes(buffer, boxes, 3, None, visibility)
    check(r == HOMCULL_OK, f"homcull_buffer_test_boxes: {r} {lib.homcull_last_error()!r}")
    check(list(visibility) == expected, f"box answers {list(visibility)}, expected {expected}")

    # The same frame as a task list the caller runs itself (here, its tasks in reverse order).
    r = lib.homcull_buffer_begin_frame(buffer, ctypes.byref(view))
    check(r == HOMCULL_OK, f"homcull_buffer_begin_frame: {r} {lib.homcull_last_error()!r}")
    tasks = c_size_t(0)
    for step, r in (("begin_tasks", lib.homcull_buffer_begin_tasks(buffer)),
                    ("draw_mesh", lib.homcull_buffer_draw_mesh(buffer, mesh, None, 1)),
                    ("close_tasks", lib.homcull_buffer_close_tasks(buffer, ctypes.byref(tasks)))):
        check(r == HOMCULL_OK, f"homcull_buffer_{step}: {r} {lib.homcull_last_error()!r}")
    check(tasks.value >= 1, f"homcull_buffer_close_tasks gave {tasks.value} tasks")
    for i in reversed(range(tasks.value)):
        r = lib.homcull_buffer_run_task(buffer, i)
        check(r == HOMCULL_OK, f"homcull_buffer_run_task({i}): {r} {lib.homcull_last_error()!r}")
    r = lib.homcull_buffer_finish_tasks(buffer)
    check(r == HOMCULL_OK, f"homcull_buffer_finish_tasks: {r} {lib.homcull_last_error()!r}")
    as_tasks = (homcull_visibility * 3)(255, 255, 255)
    r = lib.homcull_buffer_test_boxes(buffer, boxes, 3, None, as_tasks)
    check(r == HOMCULL_OK and list(as_tasks) == expected, f"box answers after a task list {list(as_tasks)}, expected {expected}")

    stats = homcull_frame_stats()
    r = lib.homcull_buffer_frame_stats(buffer, ctypes.byref(stats))
    check(r == HOMCULL_OK, f"homcull_buffer_frame_stats: {r} {lib.homcull_last_error()!r}")
    check(stats.draw_calls == 1, f"frame stats: draw_calls {stats.draw_calls}, expected 1")
    check(stats.triangles_in == 2, f"frame stats: triangles_in {stats.triangles_in}, expected 2")
    check(stats.triangles_drawn > 0, "frame stats: no triangle drawn")

    # Errors: a result, a message on this thread, and the same message to the callback.
    check(not errors.messages, f"the error callback was called before any error: {errors.messages}")
    bad_desc = homcull_buffer_desc(width=0, height=90, samples=1, near_distance=0.1, flags=0, reserved=0)
    bad = buffer_p()
    r = lib.homcull_buffer_create(context, ctypes.byref(bad_desc), ctypes.byref(bad))
    check(r == HOMCULL_ERROR_INVALID_ARGUMENT, f"homcull_buffer_create with width 0 returned {r}, expected 1")
    check(not bad, "homcull_buffer_create failed but returned a buffer")
    message = lib.homcull_last_error()
    check(isinstance(message, bytes) and message, f"homcull_last_error() is {message!r} after a failure")
    check(errors.messages == [(HOMCULL_ERROR_INVALID_ARGUMENT, message)],
          f"the error callback saw {errors.messages}, homcull_last_error() is {message!r}")

    context_bytes = lib.homcull_context_allocated_bytes(context)
    python_bytes = sum(memory.live.values())
    check(0 < context_bytes <= python_bytes,
          f"homcull_context_allocated_bytes() is {context_bytes}, the Python allocator holds {python_bytes}")

    # A sorter over the mesh placed twice along -z: the nearer one first, from the eye at the origin.
    meshes = (mesh_p * 2)(mesh, mesh)
    sorter = sorter_p()
    made = lib.homcull_sorter_create(context, ctypes.byref(homcull_sorter_desc(ctypes.cast(meshes, c_void_p), 2)), ctypes.byref(sorter))
    check(made == HOMCULL_OK, f"homcull_sorter_create: {lib.homcull_last_error()}")
    matrices = (c_float * 32)(*([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -30, 1] + [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -8, 1]))
    sort_frame = homcull_sort_frame(model_matrices=matrices, layout=HOMCULL_COLUMN_MAJOR)
    sorted_objects = homcull_sort_result()
    made = lib.homcull_sorter_sort(sorter, ctypes.byref(sort_frame), ctypes.byref(sorted_objects))
    check(made == HOMCULL_OK, f"homcull_sorter_sort: {lib.homcull_last_error()}")
    order = [sorted_objects.order[k] for k in range(sorted_objects.order_count)]
    check(order == [1, 0], f"the sorter's order is {order}, not [1, 0] (nearest first)")
    lib.homcull_sorter_destroy(sorter)

    lib.homcull_buffer_destroy(buffer)
    lib.homcull_mesh_destroy(mesh)
    # Only the context's own block is left.
    check(lib.homcull_context_allocated_bytes(context) == sum(memory.live.values()),
          "the context counts other memory than its own block after its objects were destroyed")
    lib.homcull_context_destroy(context)
    check(not memory.live, f"{len(memory.live)} blocks of the Python allocator still live: {memory.live}")
    check(memory.frees == memory.calls, f"{memory.calls} allocations, {memory.frees} frees")
    check(not memory.problems, "allocator callbacks: " + "; ".join(memory.problems))
    check(not errors.problems, "error callback: " + "; ".join(errors.problems))

    print(f"homcull {parts['MAJOR']}.{parts['MINOR']}.{parts['PATCH']} (version {linked}) from {lib_path}")
    print(f"  {size_checks} struct sizes match the header ({8 * struct.calcsize('P')}-bit pointers)")
    print(f"  context isa {lib.homcull_isa_name(isa).decode()}, supported isas mask {isas:#x}")
    print(f"  boxes: {list(visibility)} (occluded, visible, view-culled), the same after a task list of {tasks.value} tasks")
    print(f"  frame stats: {stats.triangles_in} in, {stats.triangles_drawn} drawn, {stats.triangles_skipped} skipped,"
          f" {stats.draw_calls} draw call(s), {stats.allocations} allocation(s)")
    print(f"  error: {lib.homcull_result_name(r).decode()}: {message.decode()}")
    print(f"  sorter: order {order}, {sorted_objects.layer_count} layers")
    print(f"  Python allocator: {memory.calls} allocations ({context_bytes} bytes held by the mesh and buffer"
          f" mid-test), 0 blocks live at the end")
    print("PASS")


def main(argv):
    if len(argv) != 3:
        print(f"usage: {argv[0]} <libhomcull.so> <homcull.h>", file=sys.stderr)
        return 2
    try:
        run(argv[1], argv[2])
    except TestFailure as e:
        print(f"FAIL: {e}", file=sys.stderr)
        return 1
    except OSError as e:  # the library or the header could not be opened
        print(f"FAIL: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
