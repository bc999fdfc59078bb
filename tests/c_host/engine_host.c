/* A C99 engine host of homcull.h, as a CPU-only engine plugin would be: its own allocator
 * (counting, and able to fail on its k-th call), its own threads (queries from two threads at
 * once), and its own camera conventions (a left-handed world, reversed depth in [0, 1],
 * row-major matrices). It walks a scene written by tests/test_engine_host.cpp: it registers
 * the meshes once, draws the occluders object by object, nearest first, and tests every
 * object's box each frame, then writes the answers for the test to check against Embree and
 * against the C++ interface. It draws the walk again through its own job system (tasks taken in
 * turn by two threads), once called by the library and once as task lists it runs itself (the
 * pull model), and checks that the answers are the same and that nothing allocates after the
 * reserve.
 *
 *   engine_host [--orthographic D] WALK ANSWERS
 *                                       the walk (with orthographic cameras: see engine_view);
 *                                       exit 0, or 2 and a message when a call fails or
 *                                       the walk allocated after its reserve. ANSWERS.trace gets
 *                                       each frame's world_to_clip (16 f64) and draw order (u32
 *                                       count, u32 occluder numbers)
 *   engine_host --fail-sweep WALK OUT   for every k, the walk again with an allocator failing on
 *                                       its k-th call: every call must return OK or
 *                                       HOMCULL_ERROR_OUT_OF_MEMORY and every block come back
 *
 * The walk file (little-endian): "HCWALK1" and a zero byte; u32 samples; u32 mesh count, then
 * per mesh u32 vertices, u32 triangles, f32 x y z per vertex, u32 indices; u32 occluder count,
 * then per occluder u32 mesh and f32[16] model-to-world (column-major, right-handed world); u32
 * box count, then f32 min[3] max[3] per box (right-handed world); u32 frame count, then per
 * frame f64 eye[3] target[3] up[3], f64 fov_y (degrees), near, far, i32 width, height. */
#include <homcull/homcull.h>

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- The engine's allocator ------------------------------------------------------------- */

typedef struct {
    pthread_mutex_t lock;
    unsigned long calls, live, fail_at; /* fail_at: the call that returns null (0: none) */
} EngineMemory;

static void* engine_allocate(void* user, size_t size, size_t alignment) {
    EngineMemory* m = (EngineMemory*)user;
    void* p = NULL;
    pthread_mutex_lock(&m->lock);
    ++m->calls;
    if (m->calls != m->fail_at) {
        /* aligned_alloc is C11; posix_memalign is what a C99 engine on POSIX has. */
        if (posix_memalign(&p, alignment < sizeof(void*) ? sizeof(void*) : alignment, size) != 0) p = NULL;
        if (p) ++m->live;
    }
    pthread_mutex_unlock(&m->lock);
    return p;
}

static void engine_deallocate(void* user, void* memory, size_t size) {
    EngineMemory* m = (EngineMemory*)user;
    (void)size;
    pthread_mutex_lock(&m->lock);
    --m->live;
    pthread_mutex_unlock(&m->lock);
    free(memory);
}

/* ---- The scene as the engine holds it: a left-handed world (z mirrored on import) ----------- */

typedef struct {
    uint32_t vertices, triangles;
    float* positions;
    uint32_t* indices;
} Mesh;

typedef struct {
    uint32_t mesh;
    float model[16]; /* row-major, left-handed world */
    double centre[3];
} Occluder;

typedef struct {
    double eye[3], target[3], up[3], fov_y, near_plane, far_plane;
    int32_t width, height;
} Frame;

typedef struct {
    uint32_t samples, mesh_count, occluder_count, box_count, frame_count;
    Mesh* meshes;
    Occluder* occluders;
    homcull_box* boxes;
    Frame* frames;
} Walk;

static void fail(const char* format, ...) {
    va_list args;
    va_start(args, format);
    fprintf(stderr, "engine_host: ");
    vfprintf(stderr, format, args);
    fprintf(stderr, "\n");
    va_end(args);
    exit(2);
}

static void read_bytes(FILE* f, void* out, size_t size) {
    if (fread(out, 1, size, f) != size) fail("the walk file ends early");
}
static uint32_t read_u32(FILE* f) {
    uint32_t v;
    read_bytes(f, &v, sizeof v);
    return v;
}
static void* checked_malloc(size_t size) {
    void* p = malloc(size ? size : 1);
    if (!p) fail("out of memory reading the walk");
    return p;
}

/* The mirror z -> -z turns the file's right-handed world into the engine's left-handed one. */
static void read_walk(const char* path, Walk* w) {
    char magic[8];
    uint32_t i, k;
    FILE* f = fopen(path, "rb");
    if (!f) fail("cannot open %s", path);
    read_bytes(f, magic, 8);
    if (memcmp(magic, "HCWALK1", 8) != 0) fail("%s is not a walk file", path);
    w->samples = read_u32(f);
    w->mesh_count = read_u32(f);
    w->meshes = (Mesh*)checked_malloc(w->mesh_count * sizeof(Mesh));
    for (i = 0; i < w->mesh_count; ++i) {
        Mesh* m = &w->meshes[i];
        m->vertices = read_u32(f);
        m->triangles = read_u32(f);
        m->positions = (float*)checked_malloc((size_t)m->vertices * 3 * sizeof(float));
        m->indices = (uint32_t*)checked_malloc((size_t)m->triangles * 3 * sizeof(uint32_t));
        read_bytes(f, m->positions, (size_t)m->vertices * 3 * sizeof(float));
        read_bytes(f, m->indices, (size_t)m->triangles * 3 * sizeof(uint32_t));
    }
    w->occluder_count = read_u32(f);
    w->occluders = (Occluder*)checked_malloc(w->occluder_count * sizeof(Occluder));
    for (i = 0; i < w->occluder_count; ++i) {
        Occluder* o = &w->occluders[i];
        float column_major[16];
        int r, c;
        o->mesh = read_u32(f);
        if (o->mesh >= w->mesh_count) fail("occluder %u names mesh %u of %u", i, o->mesh, w->mesh_count);
        read_bytes(f, column_major, sizeof column_major);
        /* Row-major storage of mirror * model: the mirror negates row 2. */
        for (r = 0; r < 4; ++r)
            for (c = 0; c < 4; ++c) o->model[4 * r + c] = (r == 2 ? -1.0f : 1.0f) * column_major[4 * c + r];
        for (k = 0; k < 3; ++k) o->centre[k] = o->model[4 * k + 3];
    }
    w->box_count = read_u32(f);
    w->boxes = (homcull_box*)checked_malloc(w->box_count * sizeof(homcull_box));
    for (i = 0; i < w->box_count; ++i) {
        homcull_box b;
        read_bytes(f, &b, sizeof b);
        w->boxes[i] = b;
        w->boxes[i].min[2] = -b.max[2];
        w->boxes[i].max[2] = -b.min[2];
    }
    w->frame_count = read_u32(f);
    w->frames = (Frame*)checked_malloc(w->frame_count * sizeof(Frame));
    for (i = 0; i < w->frame_count; ++i) {
        Frame* fr = &w->frames[i];
        read_bytes(f, fr->eye, sizeof fr->eye);
        read_bytes(f, fr->target, sizeof fr->target);
        read_bytes(f, fr->up, sizeof fr->up);
        read_bytes(f, &fr->fov_y, sizeof fr->fov_y);
        read_bytes(f, &fr->near_plane, sizeof fr->near_plane);
        read_bytes(f, &fr->far_plane, sizeof fr->far_plane);
        read_bytes(f, &fr->width, sizeof fr->width);
        read_bytes(f, &fr->height, sizeof fr->height);
        fr->eye[2] = -fr->eye[2];
        fr->target[2] = -fr->target[2];
        fr->up[2] = -fr->up[2];
    }
    fclose(f);
}

static void free_walk(Walk* w) {
    uint32_t i;
    for (i = 0; i < w->mesh_count; ++i) {
        free(w->meshes[i].positions);
        free(w->meshes[i].indices);
    }
    free(w->meshes);
    free(w->occluders);
    free(w->boxes);
    free(w->frames);
}

/* ---- The engine's camera: left-handed look-at, reversed-depth [0, 1] perspective ------------- */

static void normalize3(double v[3]) {
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v[0] /= l, v[1] /= l, v[2] /= l;
}
static void cross3(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* --orthographic D: every frame's camera is orthographic, its view as high as the perspective
 * one's at distance D (2 tan(fov_y / 2) D), as the test's cameras are. 0: perspective. */
static double orthographic_distance = 0.0;

/* world_to_clip = projection * view, row-major. */
static void engine_view(const Frame* fr, homcull_view* v) {
    double f[3], s[3], u[3], view[16], proj[16];
    const double aspect = (double)fr->width / (double)fr->height;
    const double y_scale = 1.0 / tan(fr->fov_y * 3.14159265358979323846 / 360.0), x_scale = y_scale / aspect;
    const double n = fr->near_plane, fa = fr->far_plane;
    int r, c, k;
    memset(v, 0, sizeof *v);
    f[0] = fr->target[0] - fr->eye[0], f[1] = fr->target[1] - fr->eye[1], f[2] = fr->target[2] - fr->eye[2];
    normalize3(f);
    cross3(fr->up, f, s); /* left-handed: right = up x forward */
    normalize3(s);
    cross3(f, s, u);
    memset(view, 0, sizeof view);
    for (k = 0; k < 3; ++k) view[0 * 4 + k] = s[k], view[1 * 4 + k] = u[k], view[2 * 4 + k] = f[k];
    view[0 * 4 + 3] = -dot3(s, fr->eye), view[1 * 4 + 3] = -dot3(u, fr->eye), view[2 * 4 + 3] = -dot3(f, fr->eye);
    view[15] = 1.0;
    memset(proj, 0, sizeof proj);
    if (orthographic_distance > 0.0) {
        const double half_height = orthographic_distance / y_scale; /* tan(fov_y / 2) D */
        proj[0] = 1.0 / (half_height * aspect);
        proj[5] = 1.0 / half_height;
        proj[10] = -1.0 / (fa - n); /* reversed: z is 1 at the near plane, 0 at the far one */
        proj[11] = fa / (fa - n);
        proj[15] = 1.0; /* w = 1 */
    } else {
        proj[0] = x_scale;
        proj[5] = y_scale;
        proj[10] = -n / (fa - n); /* reversed: z/w is 1 at the near plane, 0 at the far one */
        proj[11] = n * fa / (fa - n);
        proj[14] = 1.0; /* w = view depth */
    }
    for (r = 0; r < 4; ++r)
        for (c = 0; c < 4; ++c) {
            double sum = 0.0;
            for (k = 0; k < 4; ++k) sum += proj[4 * r + k] * view[4 * k + c];
            v->world_to_clip[4 * r + c] = sum;
        }
    v->layout = HOMCULL_ROW_MAJOR;
    v->depth_range = HOMCULL_DEPTH_ZERO_TO_ONE;
    v->front_face = HOMCULL_FRONT_CCW;
    v->cull = HOMCULL_CULL_BACK;
    v->flags = HOMCULL_VIEW_REVERSED_Z;
}

/* ---- The engine's threads: the boxes answered in two halves at once ----------------------- */

typedef struct {
    const homcull_buffer* buffer;
    const homcull_box* boxes;
    size_t count;
    homcull_visibility* answers;
    homcull_result result;
} QueryJob;

static void* run_query(void* data) {
    QueryJob* j = (QueryJob*)data;
    j->result = homcull_buffer_test_boxes(j->buffer, j->boxes, j->count, NULL, j->answers);
    return NULL;
}

static homcull_result test_boxes_on_two_threads(const homcull_buffer* buffer, const Walk* w, homcull_visibility* answers) {
    QueryJob jobs[2];
    pthread_t thread;
    const size_t half = w->box_count / 2;
    jobs[0].buffer = jobs[1].buffer = buffer;
    jobs[0].boxes = w->boxes, jobs[0].count = half, jobs[0].answers = answers;
    jobs[1].boxes = w->boxes + half, jobs[1].count = w->box_count - half, jobs[1].answers = answers + half;
    if (pthread_create(&thread, NULL, run_query, &jobs[1]) != 0) {
        run_query(&jobs[1]); /* no thread: the same answers on this one */
        run_query(&jobs[0]);
    } else {
        run_query(&jobs[0]);
        pthread_join(thread, NULL);
    }
    return jobs[0].result != HOMCULL_OK ? jobs[0].result : jobs[1].result;
}

/* ---- The engine's job system: tasks taken in turn by the calling thread and one more --------- */

typedef struct {
    void (*task)(void*, size_t);
    void* data;
    size_t count, next;
    pthread_mutex_t lock;
} JobBatch;

static void* take_jobs(void* data) {
    JobBatch* b = (JobBatch*)data;
    for (;;) {
        size_t i;
        pthread_mutex_lock(&b->lock);
        i = b->next++;
        pthread_mutex_unlock(&b->lock);
        if (i >= b->count) return NULL;
        b->task(b->data, i);
    }
}

static void run_jobs(void* user, size_t count, void (*task)(void* task_data, size_t index), void* task_data) {
    JobBatch b;
    pthread_t helper;
    int started;
    (void)user;
    b.task = task, b.data = task_data, b.count = count, b.next = 0;
    pthread_mutex_init(&b.lock, NULL);
    started = pthread_create(&helper, NULL, take_jobs, &b) == 0;
    take_jobs(&b);
    if (started) pthread_join(helper, NULL);
    pthread_mutex_destroy(&b.lock);
}

/* The pull model: the buffer's tasks, run by the engine's job system. */
static void run_buffer_task(void* buffer, size_t index) {
    const homcull_result r = homcull_buffer_run_task((homcull_buffer*)buffer, index);
    if (r != HOMCULL_OK) fail("homcull_buffer_run_task(%lu): %s (%s)", (unsigned long)index, homcull_result_name(r), homcull_last_error());
}

/* How a walk draws: on the calling thread, through the engine's job system (the library calls
 * it), or as task lists the engine runs itself (the pull model). */
enum { DRAW_ON_CALLER, DRAW_THROUGH_JOBS, DRAW_AS_TASKS };

/* ---- The walk ------------------------------------------------------------------------------- */

typedef struct {
    const Frame* frame;
    const Occluder* occluder;
    double distance2;
} DrawItem;

static const double* sort_eye;
static int nearest_first(const void* a, const void* b) {
    const double da = ((const DrawItem*)a)->distance2, db = ((const DrawItem*)b)->distance2;
    return da < db ? -1 : da > db ? 1 : 0;
}

/* Whether a result is one the sweep accepts: OK, or out of memory while its allocator fails. */
static int acceptable(homcull_result r, int sweeping, const char* what) {
    if (r == HOMCULL_OK || (sweeping && r == HOMCULL_ERROR_OUT_OF_MEMORY)) return r == HOMCULL_OK;
    fail("%s: %s (%s)", what, homcull_result_name(r), homcull_last_error());
    return 0;
}

/* Runs the walk (its first `frames` frames) with an allocator failing on call fail_at (0: none),
 * writing each frame's answers to `answers` (box_count each; all visible where nothing could
 * be answered). Returns the allocator's calls; *walk_allocations gets those after the reserve. */
static unsigned long run_walk(const Walk* w, uint32_t frames, unsigned long fail_at, homcull_visibility* answers,
                              unsigned long* walk_allocations, FILE* trace, int drawing) {
    EngineMemory memory;
    homcull_context_desc desc;
    homcull_context* context = NULL;
    homcull_mesh** meshes;
    homcull_buffer* buffer = NULL;
    homcull_buffer_desc bd;
    homcull_reserve_desc reserve;
    DrawItem* items;
    unsigned long calls_after_reserve = 0;
    const int sweeping = fail_at != 0;
    uint32_t i, f, largest = 0;
    size_t all_triangles = 0;
    int32_t width = 0, height = 0;
    double near_plane = 0.0;

    memset(&memory, 0, sizeof memory);
    pthread_mutex_init(&memory.lock, NULL);
    memory.fail_at = fail_at;
    memset(&desc, 0, sizeof desc);
    desc.allocator.allocate = engine_allocate;
    desc.allocator.deallocate = engine_deallocate;
    desc.allocator.user = &memory;
    desc.isa = HOMCULL_ISA_BEST;
    memset(answers, HOMCULL_VISIBLE, (size_t)frames * w->box_count);
    meshes = (homcull_mesh**)checked_malloc(w->mesh_count * sizeof *meshes);
    items = (DrawItem*)checked_malloc(w->occluder_count * sizeof *items);
    for (i = 0; i < w->mesh_count; ++i) meshes[i] = NULL;

    if (acceptable(homcull_context_create(&desc, &context), sweeping, "homcull_context_create")) {
        for (i = 0; i < w->mesh_count; ++i) {
            homcull_mesh_desc md;
            memset(&md, 0, sizeof md);
            md.positions = w->meshes[i].positions;
            md.position_stride = 3 * sizeof(float);
            md.vertex_count = w->meshes[i].vertices;
            md.indices = w->meshes[i].indices;
            md.index_size = 4;
            md.triangle_count = w->meshes[i].triangles;
            if (w->meshes[i].triangles > largest) largest = w->meshes[i].triangles;
            acceptable(homcull_mesh_create(context, &md, &meshes[i]), sweeping, "homcull_mesh_create");
        }
        for (f = 0; f < frames; ++f) {
            if (w->frames[f].width > width) width = w->frames[f].width;
            if (w->frames[f].height > height) height = w->frames[f].height;
        }
        memset(&bd, 0, sizeof bd);
        bd.width = w->frames[0].width, bd.height = w->frames[0].height, bd.samples = (int32_t)w->samples;
        bd.near_distance = (float)w->frames[0].near_plane;
        if (acceptable(homcull_buffer_create(context, &bd, &buffer), sweeping, "homcull_buffer_create")) {
            memset(&reserve, 0, sizeof reserve);
            for (i = 0; i < w->occluder_count; ++i) all_triangles += w->meshes[w->occluders[i].mesh].triangles;
            reserve.max_width = width, reserve.max_height = height, reserve.max_draw_triangles = largest;
            reserve.max_task_list_draws = w->occluder_count, reserve.max_task_list_triangles = all_triangles;
            reserve.max_job_threads = 2;
            acceptable(homcull_buffer_reserve(buffer, &reserve), sweeping, "homcull_buffer_reserve");
            if (drawing == DRAW_THROUGH_JOBS) {
                homcull_job_system jobs;
                memset(&jobs, 0, sizeof jobs);
                jobs.run = run_jobs, jobs.threads = 2;
                acceptable(homcull_buffer_set_job_system(buffer, &jobs), sweeping, "homcull_buffer_set_job_system");
            }
        }
    }
    calls_after_reserve = memory.calls;
    width = buffer ? w->frames[0].width : 0, height = buffer ? w->frames[0].height : 0;
    near_plane = w->frames[0].near_plane;

    for (f = 0; buffer && f < frames; ++f) {
        const Frame* fr = &w->frames[f];
        homcull_view view;
        homcull_frame_stats stats;
        homcull_result r;
        uint32_t n = 0;
        if (fr->width != width || fr->height != height) { /* a resolution change in mid-walk */
            if (!acceptable(homcull_buffer_set_resolution(buffer, fr->width, fr->height), sweeping, "homcull_buffer_set_resolution")) continue;
            width = fr->width, height = fr->height;
        }
        if (fr->near_plane != near_plane) { /* a near-plane change in mid-walk */
            acceptable(homcull_buffer_set_near(buffer, (float)fr->near_plane), sweeping, "homcull_buffer_set_near");
            near_plane = fr->near_plane;
        }
        engine_view(fr, &view);
        if (!acceptable(homcull_buffer_begin_frame(buffer, &view), sweeping, "homcull_buffer_begin_frame")) continue;
        /* Occluders object by object, nearest first, as an engine's scene traversal would. */
        sort_eye = fr->eye;
        for (i = 0; i < w->occluder_count; ++i) {
            const double* c = w->occluders[i].centre;
            const double d[3] = {c[0] - sort_eye[0], c[1] - sort_eye[1], c[2] - sort_eye[2]};
            if (!meshes[w->occluders[i].mesh]) continue; /* its registration ran out of memory */
            items[n].frame = fr, items[n].occluder = &w->occluders[i], items[n].distance2 = dot3(d, d);
            ++n;
        }
        qsort(items, n, sizeof *items, nearest_first);
        if (drawing == DRAW_AS_TASKS) acceptable(homcull_buffer_begin_tasks(buffer), sweeping, "homcull_buffer_begin_tasks");
        for (i = 0; i < n; ++i)
            acceptable(homcull_buffer_draw_mesh(buffer, meshes[items[i].occluder->mesh], items[i].occluder->model, 1), sweeping,
                       "homcull_buffer_draw_mesh");
        if (drawing == DRAW_AS_TASKS) {
            size_t tasks = 0;
            if (acceptable(homcull_buffer_close_tasks(buffer, &tasks), sweeping, "homcull_buffer_close_tasks")) {
                run_jobs(NULL, tasks, run_buffer_task, buffer);
                acceptable(homcull_buffer_finish_tasks(buffer), sweeping, "homcull_buffer_finish_tasks");
            } else if (homcull_buffer_finish_tasks(buffer) != HOMCULL_ERROR_INVALID_OPERATION) { /* ends the unclosed list */
                fail("homcull_buffer_finish_tasks of an unclosed list did not say so");
            }
        }
        if (trace) { /* the camera and the draw order, for the test to replay through the C++ interface */
            if (fwrite(view.world_to_clip, sizeof view.world_to_clip, 1, trace) != 1 || fwrite(&n, 4, 1, trace) != 1) fail("cannot write the trace");
            for (i = 0; i < n; ++i) {
                const uint32_t number = (uint32_t)(items[i].occluder - w->occluders);
                if (fwrite(&number, 4, 1, trace) != 1) fail("cannot write the trace");
            }
        }
        r = test_boxes_on_two_threads(buffer, w, answers + (size_t)f * w->box_count);
        if (r != HOMCULL_OK) fail("homcull_buffer_test_boxes: %s (%s)", homcull_result_name(r), homcull_last_error());
        if (homcull_buffer_frame_stats(buffer, &stats) != HOMCULL_OK) fail("homcull_buffer_frame_stats failed");
        if (!sweeping && stats.allocations != 0) fail("frame %u allocated %lu times after the reserve", f, (unsigned long)stats.allocations);
    }
    if (walk_allocations) *walk_allocations = memory.calls - calls_after_reserve;

    homcull_buffer_destroy(buffer);
    for (i = 0; i < w->mesh_count; ++i) homcull_mesh_destroy(meshes[i]);
    homcull_context_destroy(context);
    if (memory.live != 0) fail("%lu blocks of the engine's memory were not given back (failing call %lu)", memory.live, fail_at);
    free(meshes);
    free(items);
    pthread_mutex_destroy(&memory.lock);
    return memory.calls;
}

static void write_answers(const char* path, uint32_t runs, uint32_t frames, uint32_t boxes, const homcull_visibility* answers) {
    FILE* f = fopen(path, "wb");
    if (!f) fail("cannot write %s", path);
    if (fwrite(&runs, 4, 1, f) != 1 || fwrite(&frames, 4, 1, f) != 1 || fwrite(&boxes, 4, 1, f) != 1 ||
        fwrite(answers, 1, (size_t)runs * frames * boxes, f) != (size_t)runs * frames * boxes)
        fail("cannot write %s", path);
    fclose(f);
}

int main(int argc, char** argv) {
    Walk walk;
    homcull_visibility* answers;
    int sweep;
    if (argc > 2 && strcmp(argv[1], "--orthographic") == 0) {
        orthographic_distance = atof(argv[2]);
        if (!(orthographic_distance > 0.0)) fail("--orthographic needs a positive distance, got %s", argv[2]);
        argc -= 2, argv += 2;
    }
    sweep = argc == 4 && strcmp(argv[1], "--fail-sweep") == 0;
    if (argc != 3 && !sweep) {
        fprintf(stderr, "usage: engine_host [--orthographic D] [--fail-sweep] WALK ANSWERS\n");
        return 1;
    }
    if (homcull_version() != HOMCULL_VERSION) fail("built with homcull.h %d, linked with %u", HOMCULL_VERSION, homcull_version());
    read_walk(argv[1 + sweep], &walk);
    if (!sweep) {
        unsigned long after_reserve = 0, calls;
        answers = (homcull_visibility*)checked_malloc((size_t)walk.frame_count * walk.box_count);
        char trace_path[4096];
        FILE* trace;
        snprintf(trace_path, sizeof trace_path, "%s.trace", argv[2]);
        trace = fopen(trace_path, "wb");
        if (!trace) fail("cannot write %s", trace_path);
        calls = run_walk(&walk, walk.frame_count, 0, answers, &after_reserve, trace, DRAW_ON_CALLER);
        fclose(trace);
        if (after_reserve != 0) fail("the walk allocated %lu times after the reserve", after_reserve);
        {   /* The same walk drawn through the engine's job system, and as task lists it runs itself:
             * the same answers, and nothing allocated after the reserve. */
            homcull_visibility* threaded = (homcull_visibility*)checked_malloc((size_t)walk.frame_count * walk.box_count);
            run_walk(&walk, walk.frame_count, 0, threaded, &after_reserve, NULL, DRAW_THROUGH_JOBS);
            if (memcmp(answers, threaded, (size_t)walk.frame_count * walk.box_count) != 0)
                fail("the walk drawn through the job system answers differently from the calling thread");
            if (after_reserve != 0) fail("the walk through the job system allocated %lu times after the reserve", after_reserve);
            run_walk(&walk, walk.frame_count, 0, threaded, &after_reserve, NULL, DRAW_AS_TASKS);
            if (memcmp(answers, threaded, (size_t)walk.frame_count * walk.box_count) != 0)
                fail("the walk drawn as task lists answers differently from the calling thread");
            if (after_reserve != 0) fail("the walk as task lists allocated %lu times after the reserve", after_reserve);
            free(threaded);
        }
        printf("engine_host: %u frames, %u occluders drawn one by one, %u boxes; %lu allocations, none after the reserve; "
               "the same answers, and none after the reserve, through the job system and as task lists\n",
               walk.frame_count, walk.occluder_count, walk.box_count, calls);
        write_answers(argv[2], 1, walk.frame_count, walk.box_count, answers);
    } else {
        /* Every k from 1 to one past the calls of a clean walk: the last run fails nothing. */
        const size_t per_run = (size_t)walk.frame_count * walk.box_count;
        unsigned long total, k;
        homcull_visibility* all;
        answers = (homcull_visibility*)checked_malloc(per_run);
        total = run_walk(&walk, walk.frame_count, 0, answers, NULL, NULL, DRAW_ON_CALLER);
        free(answers);
        all = (homcull_visibility*)checked_malloc((total + 1) * per_run);
        for (k = 1; k <= total + 1; ++k) run_walk(&walk, walk.frame_count, k, all + (k - 1) * per_run, NULL, NULL, DRAW_ON_CALLER);
        printf("engine_host: %lu runs, each failing one allocation of %lu; every call returned OK or out of memory, every block came back\n",
               total + 1, total);
        write_answers(argv[3], (uint32_t)(total + 1), walk.frame_count, walk.box_count, all);
        free(all);
        free_walk(&walk);
        return 0;
    }
    free(answers);
    free_walk(&walk);
    return 0;
}
