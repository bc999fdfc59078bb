/* homcull: the engine-facing interface, in C99.
 *
 * A CPU occlusion culler for engines: the engine draws its occluders (registered meshes, or
 * triangles as they come) into an occlusion buffer, then asks whether boxes, screen rectangles
 * or occludee triangles are hidden behind them. Answers are conservative: "occluded" only when
 * every sample of the buffer's grid the occludee could cover holds an occluder certainly
 * nearer (docs/engine-interface.md has the guarantees and the conventions in full).
 *
 * Objects. A context holds the engine's allocator, error callback and instruction set. Meshes
 * (registered once, at load time) and buffers (one per view) are made from a context and must
 * be destroyed before it. Every byte the library uses comes from the context's allocator.
 *
 * Errors. Every call that can fail returns a homcull_result; no C++ exception ever leaves the
 * library. The message of the last error on the calling thread is homcull_last_error(), and
 * the context's error callback receives it too. Out of memory leaves every object usable;
 * a query that cannot be answered answers HOMCULL_VISIBLE.
 *
 * Threads. A context and its meshes may be used from any thread. A buffer's draws, frames and
 * settings must not overlap any other call on the same buffer; its queries may run on many
 * threads at once. The library makes no threads; draws can run as tasks of the engine's job
 * system (homcull_buffer_set_job_system).
 *
 * Frames cost what they draw. A draw call costs its own triangles plus a few microseconds,
 * whatever the resolution: drawing occluders object by object, interleaved with queries during
 * the engine's scene traversal, is as cheap as drawing them in one call. After
 * homcull_buffer_reserve, no draw within the reserved sizes (on the calling thread) and no
 * query allocates.
 */
#ifndef HOMCULL_H
#define HOMCULL_H

#include <stddef.h>
#include <stdint.h>

#define HOMCULL_VERSION_MAJOR 0
#define HOMCULL_VERSION_MINOR 2
#define HOMCULL_VERSION_PATCH 1
/* major * 10000 + minor * 100 + patch, as homcull_version() returns it. */
#define HOMCULL_VERSION (HOMCULL_VERSION_MAJOR * 10000 + HOMCULL_VERSION_MINOR * 100 + HOMCULL_VERSION_PATCH)

/* HOMCULL_API marks the exported functions. Define HOMCULL_STATIC when linking the static
 * library on Windows. Everything else in the library has hidden visibility. */
#if defined(_WIN32) && !defined(HOMCULL_STATIC)
#  if defined(HOMCULL_BUILDING)
#    define HOMCULL_API __declspec(dllexport)
#  else
#    define HOMCULL_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__)
#  define HOMCULL_API __attribute__((visibility("default")))
#else
#  define HOMCULL_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Results ------------------------------------------------------------------------------ */

typedef int32_t homcull_result;
enum {
    HOMCULL_OK = 0,
    HOMCULL_ERROR_INVALID_ARGUMENT = 1,  /* a null pointer, a number out of range, a malformed mesh */
    HOMCULL_ERROR_OUT_OF_MEMORY = 2,     /* the allocator returned null: the object is unchanged or conservative */
    HOMCULL_ERROR_UNSUPPORTED = 3,       /* an instruction set this CPU or build lacks */
    HOMCULL_ERROR_INVALID_OPERATION = 4, /* a call out of order: a query or draw before the first frame */
    HOMCULL_ERROR_INTERNAL = 5           /* a bug: please report it with the message */
};
/* A constant name for a result ("HOMCULL_ERROR_OUT_OF_MEMORY"), never null. */
HOMCULL_API const char* homcull_result_name(homcull_result result);
/* The message of the last call that failed on this thread ("" when none): what went wrong and
 * with which argument. Valid until the next failing call on this thread. */
HOMCULL_API const char* homcull_last_error(void);

/* ---- Version and instruction sets --------------------------------------------------------- */

/* HOMCULL_VERSION of the library linked: compare with the header's to catch a mismatch. */
HOMCULL_API uint32_t homcull_version(void);

typedef int32_t homcull_isa;
enum {
    HOMCULL_ISA_BEST = 0,   /* the best this CPU supports */
    HOMCULL_ISA_SCALAR = 1, /* the plain reference path (no SIMD) */
    HOMCULL_ISA_SSE4 = 2,
    HOMCULL_ISA_AVX2 = 3,
    HOMCULL_ISA_AVX512 = 4,
    HOMCULL_ISA_NEON = 5,
    HOMCULL_ISA_SVE = 6,
    HOMCULL_ISA_SVE2 = 7,
    HOMCULL_ISA_EMU128 = 8, /* Highway's portable 128-bit emulation */
    HOMCULL_ISA_COUNT = 9
};
/* Bit (1u << isa) set for every instruction set this CPU and build can run (SCALAR always).
 * Every one gives the same bits. */
HOMCULL_API uint32_t homcull_supported_isas(void);
/* "avx2", "scalar", ...; "unknown" out of range. */
HOMCULL_API const char* homcull_isa_name(homcull_isa isa);

/* ---- Context -------------------------------------------------------------------------------- */

/* The engine's memory. allocate returns size bytes aligned to alignment (a power of two, at most
 * 64) or null; deallocate frees a block allocate returned, with the size it was asked for (the
 * library never passes null). Called from any thread that calls the library. Give both or
 * neither: both null means the C library's aligned_alloc and free. */
typedef struct homcull_allocator {
    void* (*allocate)(void* user, size_t size, size_t alignment);
    void (*deallocate)(void* user, void* memory, size_t size);
    void* user;
} homcull_allocator;

/* Called on the failing thread before the call returns its error (homcull_context_create's
 * errors too, through the desc's callback). */
typedef void (*homcull_error_callback)(void* user, homcull_result result, const char* message);

typedef struct homcull_context_desc {
    homcull_allocator allocator;
    homcull_error_callback on_error; /* may be null */
    void* error_user;
    homcull_isa isa;                 /* HOMCULL_ISA_BEST, or one of homcull_supported_isas() */
    uint32_t reserved;               /* 0 */
} homcull_context_desc;

typedef struct homcull_context homcull_context;

HOMCULL_API homcull_result homcull_context_create(const homcull_context_desc* desc, homcull_context** out);
/* Null is ignored. Its meshes and buffers must be destroyed first. */
HOMCULL_API void homcull_context_destroy(homcull_context* context);
/* The instruction set the context's calls run (BEST resolved). */
HOMCULL_API homcull_isa homcull_context_isa(const homcull_context* context);
/* Bytes the context and its objects hold from its allocator right now (the context's own block
 * included). */
HOMCULL_API uint64_t homcull_context_allocated_bytes(const homcull_context* context);

/* ---- Meshes: occluder geometry registered once ------------------------------------------------ */

typedef struct homcull_mesh_desc {
    const float* positions;   /* x, y, z at the start of every position_stride bytes */
    size_t position_stride;   /* bytes, at least 12 */
    size_t vertex_count;
    const void* indices;      /* index_size bytes each, 3 per triangle; null: vertices 3t, 3t+1, 3t+2 */
    uint32_t index_size;      /* 2 or 4 (ignored without indices) */
    uint32_t reserved;        /* 0 */
    size_t triangle_count;
} homcull_mesh_desc;

typedef struct homcull_mesh homcull_mesh;

/* Copies the mesh, finds the edges its triangles share (drawn without a coverage margin where
 * the neighbour lies across the edge in the view, so that the mesh leaves no cracks) and splits
 * it into clusters of nearby triangles (skipped as a whole when outside the view or hidden).
 * Load time: allocates about 200 bytes a triangle. An index out of range is an error. */
HOMCULL_API homcull_result homcull_mesh_create(homcull_context* context, const homcull_mesh_desc* desc, homcull_mesh** out);
HOMCULL_API void homcull_mesh_destroy(homcull_mesh* mesh);
HOMCULL_API size_t homcull_mesh_triangle_count(const homcull_mesh* mesh);

/* ---- Conventions --------------------------------------------------------------------------- */

/* How the 16 numbers of a matrix are stored. The matrix maps column vectors: clip = M * p.
 * COLUMN_MAJOR: element (row r, column c) at [4c + r] (glm, OpenGL, Vulkan, and DirectXMath's
 * XMMATRIX, whose row-vector convention stores the same numbers); ROW_MAJOR: at [4r + c]. */
typedef int32_t homcull_matrix_layout;
enum { HOMCULL_COLUMN_MAJOR = 0, HOMCULL_ROW_MAJOR = 1 };

/* The clip-space depth range of the projection: OpenGL's z/w in [-1, 1], or D3D's, Vulkan's and
 * Metal's [0, 1]. With reversed depth the far plane is at -1 (or 0) and the near one at 1. */
typedef int32_t homcull_depth_range;
enum { HOMCULL_DEPTH_MINUS_ONE_TO_ONE = 0, HOMCULL_DEPTH_ZERO_TO_ONE = 1 };

typedef int32_t homcull_winding;
enum { HOMCULL_FRONT_CCW = 0, HOMCULL_FRONT_CW = 1 };

typedef int32_t homcull_cull;
enum { HOMCULL_CULL_BACK = 0, HOMCULL_CULL_NONE = 1, HOMCULL_CULL_FRONT = 2 };

enum {
    HOMCULL_VIEW_REVERSED_Z = 1u,  /* depth runs from 1 (near) to 0 or -1 (far) */
    HOMCULL_VIEW_INFINITE_FAR = 2u,/* no far plane: nothing is culled for its distance */
    HOMCULL_VIEW_Y_DOWN = 4u       /* clip y points down the screen (Vulkan without a flipped viewport) */
};

/* A frame's camera: a perspective projection whose clip w is the view depth (every standard
 * perspective matrix, left- or right-handed, reversed or infinite; clip w at least the buffer's
 * near distance is in front of the near plane), or an orthographic one (its w row (0, 0, 0, c),
 * c > 0; its near and far planes are those of its depth range, and it has a far plane: no
 * HOMCULL_VIEW_INFINITE_FAR). An orthographic frame culls what lies beyond its far plane, and
 * leaves what lies beyond twice the far distance visible.
 * The winding is the one the engine's own rasterizer calls front, as it sees the screen. */
typedef struct homcull_view {
    double world_to_clip[16];       /* projection * view, in `layout` */
    homcull_matrix_layout layout;   /* of world_to_clip and of every model matrix drawn or tested */
    homcull_depth_range depth_range;
    homcull_winding front_face;
    homcull_cull cull;              /* which occluder faces are not drawn */
    uint32_t flags;                 /* HOMCULL_VIEW_* */
    uint32_t reserved;              /* 0 */
} homcull_view;

/* ---- Occluder selection ------------------------------------------------------------------------ */

/* Zhang's complexity filter (docs/scene-culling.md, "Occluder selection"): an occluder should
 * hide much for few triangles, and railings, spiral stairs or finely tessellated patches cover
 * little for their cost. For `count` candidates, candidate k being meshes[k] under the model
 * matrix model_matrices + 16 k (in `layout`; model_matrices NULL: every one the identity),
 * keep[k] becomes 1 when its triangles per unit of its own world surface are at most `factor`
 * times the median of the candidates', else 0; a candidate without surface (degenerate
 * triangles only, or a coordinate that is not finite after the matrix) is not kept. factor <= 0
 * keeps every candidate. The scene culler's default factor is 256. Meant for load time, or when
 * the candidates change: it reads every triangle and allocates two doubles per candidate. A null
 * mesh, a matrix with a number that is not finite, an unknown layout, a factor that is NaN and
 * running out of memory are errors (keep then all 1). */
HOMCULL_API homcull_result homcull_filter_by_complexity(homcull_context* context, const homcull_mesh* const* meshes,
                                                        const float* model_matrices, homcull_matrix_layout layout, size_t count,
                                                        double factor, uint8_t* keep);

/* ---- Buffers --------------------------------------------------------------------------------- */

enum {
    HOMCULL_BUFFER_SAMPLE_DEPTH = 1u /* keep a depth per sample too: tighter occludee-triangle tests, 4 bytes a sample */
};

typedef struct homcull_buffer_desc {
    int32_t width, height;  /* pixels, 1 to 65536 */
    int32_t samples;        /* S x S samples per pixel: 1, 2 or 4 */
    float near_distance;    /* clip w of the near plane (the camera's near distance), at least 2^-126 */
    uint32_t flags;         /* HOMCULL_BUFFER_* */
    uint32_t reserved;      /* 0 */
} homcull_buffer_desc;

/* The largest work the engine will give a buffer: after homcull_buffer_reserve, frames within
 * these sizes never allocate. Zeros keep what the buffer already holds. */
typedef struct homcull_reserve_desc {
    int32_t max_width, max_height;  /* largest resolution set_resolution will be asked for */
    size_t max_draw_triangles;      /* the most triangles one draw call carries (an instanced draw: per instance) */
    size_t max_draw_vertices;       /* the most vertices one homcull_buffer_draw_triangles call carries */
    /* Task lists (homcull_buffer_begin_tasks): the most mesh draws (instances counted each) one
     * list records, and the most triangles of all their meshes. */
    size_t max_task_list_draws, max_task_list_triangles;
    /* homcull_buffer_draw_triangles through a job system: the most threads it reports
     * (homcull_job_system::threads; one that reports 0 counts as 2). 0: not reserved for. */
    uint32_t max_job_threads;
    uint32_t reserved; /* 0 */
} homcull_reserve_desc;

typedef struct homcull_buffer homcull_buffer;

HOMCULL_API homcull_result homcull_buffer_create(homcull_context* context, const homcull_buffer_desc* desc, homcull_buffer** out);
HOMCULL_API void homcull_buffer_destroy(homcull_buffer* buffer);
/* A new resolution or near distance, keeping the memory the buffer holds (it grows only when the
 * new resolution needs more than it ever had or was reserved). The buffer is then empty until
 * the next frame begins. On error the buffer keeps its old settings. */
HOMCULL_API homcull_result homcull_buffer_set_resolution(homcull_buffer* buffer, int32_t width, int32_t height);
HOMCULL_API homcull_result homcull_buffer_set_near(homcull_buffer* buffer, float near_distance);
HOMCULL_API homcull_result homcull_buffer_reserve(homcull_buffer* buffer, const homcull_reserve_desc* desc);
/* The engine's job system, for draws: run(user, count, task, task_data) must call
 * task(task_data, i) once for every i in [0, count), in any order, on any threads, and return
 * when every call has returned. Tasks never fail and never unwind (the library catches what
 * goes wrong inside one and reports it from the draw). The answers are the same bits as on the
 * calling thread. Null run: draws run on the calling thread (the default). A mesh draw is then
 * a task list of one draw (homcull_buffer_begin_tasks), run through `run`. */
typedef struct homcull_job_system {
    void (*run)(void* user, size_t count, void (*task)(void* task_data, size_t index), void* task_data);
    void* user;
    uint32_t threads;  /* how many threads run the tasks: a hint for splitting work (0: 2) */
    uint32_t reserved; /* 0 */
} homcull_job_system;
HOMCULL_API homcull_result homcull_buffer_set_job_system(homcull_buffer* buffer, const homcull_job_system* jobs);

/* Draws as tasks the engine's job system schedules itself (the pull model, as masked occlusion
 * culling's BinTriangles and RenderTrilist allow), beside homcull_job_system:
 *     homcull_buffer_begin_tasks(buffer);
 *     homcull_buffer_draw_mesh(buffer, ...);    any number: recorded on the calling thread
 *     homcull_buffer_close_tasks(buffer, &count);
 *     homcull_buffer_run_task(buffer, i);        for every i < count, once each, on any threads,
 *                                                at once, in any order (best taken in turn:
 *                                                the bands slowest last time come first)
 *     homcull_buffer_finish_tasks(buffer);       after every run_task returned
 * The buffer then holds the same bits as those draws made one after another without a list.
 * A task never allocates and never fails; after a reserve (max_task_list_*) nothing in the list
 * allocates. Between begin and finish, the meshes drawn must stay alive, and every other call
 * on the buffer (homcull_buffer_draw_triangles, queries, a new frame or resolution) is
 * HOMCULL_ERROR_INVALID_OPERATION (queries answer visible). finish_tasks always ends the list:
 * when some task did not run it says so (HOMCULL_ERROR_INVALID_OPERATION), and the buffer holds
 * the tasks that ran, which is conservative. */
HOMCULL_API homcull_result homcull_buffer_begin_tasks(homcull_buffer* buffer);
HOMCULL_API homcull_result homcull_buffer_close_tasks(homcull_buffer* buffer, size_t* task_count);
HOMCULL_API homcull_result homcull_buffer_run_task(homcull_buffer* buffer, size_t index);
HOMCULL_API homcull_result homcull_buffer_finish_tasks(homcull_buffer* buffer);

/* Bytes of the context's allocator the buffer holds, and how many allocations it has made. */
HOMCULL_API uint64_t homcull_buffer_allocated_bytes(const homcull_buffer* buffer);

/* Starts a frame: empties the buffer and takes the camera. */
HOMCULL_API homcull_result homcull_buffer_begin_frame(homcull_buffer* buffer, const homcull_view* view);

/* Draws a registered mesh as occluder, once per model matrix (model to world, 16 floats each in
 * the view's layout, instance_count of them; null with instance_count 1: the identity). Model
 * matrices are floats, as engines keep them; the view is double, so that a world far from the
 * origin loses nothing before the two are composed (in double, rounded once). Each
 * instance is composed with the view in double and drawn nearest cluster first. Occluders drawn
 * nearest first cull best (what is behind drawn occluders is skipped cheaply). */
HOMCULL_API homcull_result homcull_buffer_draw_mesh(homcull_buffer* buffer, const homcull_mesh* mesh, const float* model_matrices,
                                                    size_t instance_count);

/* Triangles given for one call (not registered): occluders, or occludees to test. */
typedef struct homcull_triangles {
    const float* positions;   /* x, y, z at the start of every position_stride bytes */
    size_t position_stride;   /* bytes, at least 12 */
    size_t vertex_count;
    const void* indices;      /* index_size bytes each, 3 per triangle; null: vertices 3t, 3t+1, 3t+2 */
    uint32_t index_size;      /* 2 or 4 */
    uint32_t reserved;        /* 0 */
    size_t triangle_count;
} homcull_triangles;

/* Draws triangles as occluder under a model matrix (null: identity), with a coverage margin on
 * every edge (no shared-edge information: register meshes to draw them without cracks). */
HOMCULL_API homcull_result homcull_buffer_draw_triangles(homcull_buffer* buffer, const homcull_triangles* triangles,
                                                         const float* model_matrix);

/* ---- Queries ------------------------------------------------------------------------------------ */

typedef uint8_t homcull_visibility;
enum {
    HOMCULL_VISIBLE = 0,     /* may be seen (and every answer the library cannot give) */
    HOMCULL_OCCLUDED = 1,    /* hidden behind the occluders drawn so far in this frame */
    HOMCULL_VIEW_CULLED = 2  /* outside the view frustum (beyond the far plane too) */
};

typedef struct homcull_box {
    float min[3];
    float max[3];
} homcull_box;

/* A screen rectangle in normalized device coordinates (in the view's y direction) and the
 * nearest view depth (clip w) of what it stands for; for an orthographic view, the nearest clip
 * z instead, in the view's depth range. */
typedef struct homcull_rect {
    float min_x, min_y, max_x, max_y;
    float nearest_w;
} homcull_rect;

/* Boxes (in model space of model_matrix; null: world boxes), count of them, answers into
 * visibility[count]. A box that does not meet the view volume (the sides and the near plane, by
 * an exact separating-axis test: a box beside a corner of the view, outside no single side, is
 * view-culled too), or lies wholly beyond the far plane (unless the view has none), is
 * view-culled, by a margin of 2^-20 of its terms; one crossing the near plane that meets the
 * volume is visible. Answers account for every occluder drawn in this frame before the call.
 * Thread-safe with other queries. */
HOMCULL_API homcull_result homcull_buffer_test_boxes(const homcull_buffer* buffer, const homcull_box* boxes, size_t count,
                                                     const float* model_matrix, homcull_visibility* visibility);
HOMCULL_API homcull_result homcull_buffer_test_rects(const homcull_buffer* buffer, const homcull_rect* rects, size_t count,
                                                     homcull_visibility* visibility);
/* An occludee by its own triangles, sample by sample: occluded when no sample any of its
 * triangles may cover (either side facing) has no occluder certainly nearer. */
HOMCULL_API homcull_result homcull_buffer_test_triangles(const homcull_buffer* buffer, const homcull_triangles* triangles,
                                                         const float* model_matrix, homcull_visibility* visibility);

enum {
    /* The occludee is a closed solid seen from outside: every edge of its triangles is shared
     * with another of them in opposite order, each connected piece encloses a volume, and the
     * whole occludee lies beyond the near plane. Its first surface along any ray is then a
     * triangle seen from the front, so the test passes over the triangles the eye certainly sees
     * from behind (about half). The caller vouches for it: an occludee that is only partly such
     * a solid may be found hidden where a back face shows. */
    HOMCULL_TRIANGLES_CLOSED_SOLID = 1u
};

/* What homcull_buffer_test_triangles_ex adds to homcull_buffer_test_triangles. All zero: the
 * same test. */
typedef struct homcull_triangle_test_desc {
    /* The triangle the scan starts from, wrapping around (none past the last: 0). The answer is
     * the same from any start; last frame's deciding_triangle finds a visible occludee's visible
     * triangle first (frame-to-frame coherence: most visible occludees then cost one triangle). */
    size_t first_triangle;
    /* Samples the occludee may show and still be answered occluded (approximate culling);
     * 0: conservative. */
    uint64_t tolerated_samples;
    uint32_t flags;       /* HOMCULL_TRIANGLES_* */
    /* HOMCULL_TRIANGLES_CLOSED_SOLID: +1 when each triangle (a, b, c)'s (b - a) x (c - a) points
     * out of the solid, -1 when into it (in the positions' own space, whatever the view's
     * front_face). */
    int32_t orientation;
    /* HOMCULL_TRIANGLES_CLOSED_SOLID: the eye (the view's centre of projection) in the
     * positions' space, the model space of model_matrix. Perspective views only. */
    double eye[3];
} homcull_triangle_test_desc;

typedef struct homcull_triangle_test_result {
    homcull_visibility visibility;
    uint8_t reserved[7];
    size_t deciding_triangle;   /* visible: the triangle found visible (next frame's first_triangle); else 0 */
    uint64_t samples;           /* samples the triangles may cover, counted up to the answer (partial when visible; with
                                   no tolerance, triangles whose bounding rectangle is hidden are passed over uncounted) */
    uint64_t visible_samples;   /* of those, the samples with no occluder certainly nearer */
} homcull_triangle_test_result;

/* homcull_buffer_test_triangles with a start triangle, a tolerance and closed solids (desc; null:
 * all zero), answering with what decided it (since 0.2.1). Errors (a closed solid in an orthographic view, an
 * orientation other than +1 or -1, an eye not finite, unknown flags) answer HOMCULL_VISIBLE. */
HOMCULL_API homcull_result homcull_buffer_test_triangles_ex(const homcull_buffer* buffer, const homcull_triangles* triangles,
                                                            const float* model_matrix, const homcull_triangle_test_desc* desc,
                                                            homcull_triangle_test_result* result);

/* What the frame drew so far. */
typedef struct homcull_frame_stats {
    uint64_t triangles_in;       /* submitted (instances counted each) */
    uint64_t triangles_drawn;    /* reached the buffer (after clipping) */
    uint64_t triangles_skipped;  /* outside the view, back-facing, degenerate, invalid or too large */
    uint64_t clusters_hidden;    /* cluster and band pairs skipped as hidden behind what was drawn */
    uint64_t draw_calls;
    uint64_t allocations;        /* allocations the buffer made during this frame (0 after a reserve) */
} homcull_frame_stats;
HOMCULL_API homcull_result homcull_buffer_frame_stats(const homcull_buffer* buffer, homcull_frame_stats* stats);

/* ---- Visibility sorting ------------------------------------------------------------------------- */

/* Orders objects front to back so that none hides part of one before it, with the occlusion
 * cycles no order can draw grouped into layers (Snyder and Lengyel's incremental visibility
 * sort; docs/visibility-sorting.md). Each object is the convex hull of a mesh's vertices, made
 * when the sorter is created; a frame gives each object's model matrix and the eye. Answers are
 * conservative for the hulls: no object ever hides part of one in an earlier layer. A sorter is
 * used from one thread at a time; sorters are independent. No allocation per frame once a
 * sorter has seen its busiest frame. */
typedef struct homcull_sorter homcull_sorter;

typedef struct homcull_sorter_desc {
    const homcull_mesh* const* object_meshes;  /* object i's mesh (one hull per distinct mesh) */
    size_t object_count;
} homcull_sorter_desc;

HOMCULL_API homcull_result homcull_sorter_create(homcull_context* context, const homcull_sorter_desc* desc, homcull_sorter** out);
HOMCULL_API void homcull_sorter_destroy(homcull_sorter* sorter);

typedef struct homcull_sort_frame {
    const float* model_matrices;        /* object_count matrices, 16 floats each, in `layout` */
    homcull_matrix_layout layout;
    float eye[3];                       /* in the world of the model matrices */
    const float* planes;                /* plane_count planes (a, b, c, d): a x + b y + c z + d >= 0
                                           inside; objects wholly outside one are left out; may be null */
    uint32_t plane_count;               /* at most 16 (the view frustum's six, say) */
    uint32_t from_scratch;              /* nonzero: not from the last frame's order (same layers) */
} homcull_sort_frame;

typedef struct homcull_sort_layer {
    uint32_t first, count;              /* objects order[first, first + count) */
} homcull_sort_layer;

typedef struct homcull_occlusion_pair {
    uint32_t occluder, occluded;
} homcull_occlusion_pair;

/* A sort's answer, valid until the sorter's next sort or its destruction. */
typedef struct homcull_sort_result {
    const uint32_t* order;              /* the sorted objects (left out ones are not), front to back */
    size_t order_count;
    const homcull_sort_layer* layers;   /* front to back; a layer of more than one is a cycle */
    size_t layer_count;
    const homcull_occlusion_pair* pairs;/* the occlusions its tests found */
    size_t pair_count;
    uint32_t cycles;                    /* layers of more than one object */
    uint32_t objects_in_cycles;
} homcull_sort_result;

/* Objects whose matrix is not finite are left out. */
HOMCULL_API homcull_result homcull_sorter_sort(homcull_sorter* sorter, const homcull_sort_frame* frame, homcull_sort_result* out);

/* ---- Layout checks: the sizes both sides of the interface agree on ---------------------------- */

#define HOMCULL_CHECK_SIZE_(name, type, size) typedef char homcull_size_check_##name[(sizeof(type) == (size)) ? 1 : -1]
HOMCULL_CHECK_SIZE_(box, homcull_box, 24);
HOMCULL_CHECK_SIZE_(rect, homcull_rect, 20);
HOMCULL_CHECK_SIZE_(view, homcull_view, 152);
HOMCULL_CHECK_SIZE_(buffer_desc, homcull_buffer_desc, 24);
HOMCULL_CHECK_SIZE_(frame_stats, homcull_frame_stats, 48);
HOMCULL_CHECK_SIZE_(allocator, homcull_allocator, 3 * sizeof(void*));
HOMCULL_CHECK_SIZE_(context_desc, homcull_context_desc, 5 * sizeof(void*) + 8);
HOMCULL_CHECK_SIZE_(mesh_desc, homcull_mesh_desc, 5 * sizeof(void*) + 8);
HOMCULL_CHECK_SIZE_(triangles, homcull_triangles, 5 * sizeof(void*) + 8);
HOMCULL_CHECK_SIZE_(reserve_desc, homcull_reserve_desc, 16 + 4 * sizeof(size_t));
HOMCULL_CHECK_SIZE_(job_system, homcull_job_system, 2 * sizeof(void*) + 8);
HOMCULL_CHECK_SIZE_(sorter_desc, homcull_sorter_desc, 2 * sizeof(void*));
HOMCULL_CHECK_SIZE_(sort_frame, homcull_sort_frame, 2 * sizeof(void*) + 24);
HOMCULL_CHECK_SIZE_(sort_layer, homcull_sort_layer, 8);
HOMCULL_CHECK_SIZE_(occlusion_pair, homcull_occlusion_pair, 8);
HOMCULL_CHECK_SIZE_(sort_result, homcull_sort_result, 6 * sizeof(void*) + 8);

#ifdef __cplusplus
}
#endif

#endif /* HOMCULL_H */
