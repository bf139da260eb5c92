/* The model as a DPI-C reference for SystemVerilog testbenches (docs/dpi.md): a plain C ABI that
 * rtl/dpi/saarcor_dpi_pkg.sv imports with `import "DPI-C"`, so any simulator that supports DPI-C
 * (Verilator, VCS, Xcelium, Questa) can call the same functions the model computes with.
 *
 * Only C types that IEEE 1800 Annex H maps from SystemVerilog: `int` <-> int, `int unsigned` <->
 * unsigned int, `real` <-> double, `string` <-> const char*, outputs as pointers. Float values are
 * encodings (bit patterns) in the low bits of an unsigned int.
 *
 * Every function returns SAARCOR_DPI_OK (0) or SAARCOR_DPI_ERROR (-1); after an error,
 * saarcor_dpi_last_error() gives one line saying why, and the outputs are not written (unless
 * an output pointer is null, which no simulator passes: outputs before it may be). Calls are not
 * thread-safe: one simulator thread calls them, as DPI imports are called.
 */
#ifndef SAARCOR_DPI_H
#define SAARCOR_DPI_H

#ifdef __cplusplus
extern "C" {
#endif

#define SAARCOR_DPI_OK 0
#define SAARCOR_DPI_ERROR (-1)

/* The message of the last call that failed ("" before any failure): one line, no newline. */
const char* saarcor_dpi_last_error(void);
/* The interface's version (1): a testbench can check it matches the package it compiled. */
int saarcor_dpi_version(void);

/* ---- float operators (as `saarcor float-calc`): any format eEmM (2 <= E <= 8, 1 <= M <= 23),
 * round "rne" | "rtz", subnormals "flush" | "keep". op: add sub mul div sqrt (b unused) min max,
 * and the compares lt le eq (result 1 or 0). Operands must fit the format's 1 + E + M bits. */
int saarcor_dpi_fp_op(const char* op, int exp_bits, int man_bits, const char* round,
                      const char* subnormals, unsigned int a, unsigned int b, unsigned int* result);
/* A real rounded into the format, and an encoding's value (exact: every format fits a double). */
int saarcor_dpi_fp_from_real(double value, int exp_bits, int man_bits, const char* round,
                             const char* subnormals, unsigned int* bits);
int saarcor_dpi_fp_to_real(unsigned int bits, int exp_bits, int man_bits, const char* subnormals,
                           double* value);

/* ---- the unit datapaths (units/datapath.h) in the prototype's fp24 (e7m16), with the FP units'
 * rounding and subnormal modes; flags are 0 or 1. rtl/'s datapath modules compute the same. */
/* Traversal lane: d = (split - o_axis) / d_axis; near child unless d < tn, far unless tf < d. */
int saarcor_dpi_traversal_lane(const char* round, const char* subnormals, unsigned int split,
                               unsigned int o_axis, unsigned int d_axis, unsigned int tn,
                               unsigned int tf, int* go_near, int* go_far, unsigned int* near_tf,
                               unsigned int* far_tn);
/* Transformation step: r_i = (m_i0 x + m_i1 y) + (m_i2 z + t_i), t_i = +0 unless translate. */
int saarcor_dpi_transform_step(const char* round, const char* subnormals, unsigned int m00,
                               unsigned int m01, unsigned int m02, unsigned int t0,
                               unsigned int m10, unsigned int m11, unsigned int m12,
                               unsigned int t1, unsigned int m20, unsigned int m21,
                               unsigned int m22, unsigned int t2, unsigned int x, unsigned int y,
                               unsigned int z, int translate, unsigned int* rx, unsigned int* ry,
                               unsigned int* rz);
/* Unit-triangle intersection of a ray in unit-triangle space, and its acceptance against the
 * ray's closest hit so far (best_t, best_instance, best_triangle; no hit: t = +inf, ids
 * 0xffffffff): inside = the datapath's bit tests, accept = inside and closer (or equal t with
 * smaller ids). */
int saarcor_dpi_intersect(const char* round, const char* subnormals, unsigned int ox,
                          unsigned int oy, unsigned int oz, unsigned int dx, unsigned int dy,
                          unsigned int dz, unsigned int instance_id, unsigned int triangle_id,
                          unsigned int best_t, unsigned int best_instance,
                          unsigned int best_triangle, unsigned int* t, unsigned int* u,
                          unsigned int* v, unsigned int* c, int* inside, int* accept);

/* ---- the core's transaction-level reference on a scene's memory image, as `saarcor scene SCENE
 * --write-image FILE` writes it (docs/memory-image.md "Image file"). One image at a time: a load
 * replaces the one before; the calls below fail with "no memory image loaded" without one. */
int saarcor_dpi_load_image(const char* path);
int saarcor_dpi_unload_image(void);
int saarcor_dpi_image_info(int* width, int* height, int* exp_bits, int* man_bits, int* instances);
/* The primary ray of pixel (x, y) through the functional model (the RGC's packet of P rays that
 * holds the pixel, P = packet: 1, 2, 4, ... 64; the prototype's is 4), as `saarcor render
 * --pixel x,y`: its closest hit (instance and triangle 0xffffffff and t = +inf on a miss). */
int saarcor_dpi_trace_pixel(int x, int y, int packet, unsigned int* instance,
                            unsigned int* triangle, unsigned int* t, unsigned int* u,
                            unsigned int* v);
/* One unit's prediction on the image's data. The transformation unit's step with the matrix at
 * matrix row `row` (rows row..row+2 of the image: an instance's world -> object rows or a
 * triangle's T_delta), in the image's format and the prototype's mode (rne, flush). */
int saarcor_dpi_core_transform(unsigned int row, int translate, unsigned int x, unsigned int y,
                               unsigned int z, unsigned int* rx, unsigned int* ry,
                               unsigned int* rz);
/* The traversal unit's lane on inner kd-node `node` of the image (either level): the node's axis
 * (0, 1, 2) and split plane from the image, the ray's origin and direction in the node's space,
 * the ray's segment [tn, tf]; as saarcor_dpi_traversal_lane (fp24 images; a leaf is an error). */
int saarcor_dpi_core_traversal(unsigned int node, unsigned int ox, unsigned int oy, unsigned int oz,
                               unsigned int dx, unsigned int dy, unsigned int dz, unsigned int tn,
                               unsigned int tf, int* axis, int* go_near, int* go_far,
                               unsigned int* near_tf, unsigned int* far_tn);
/* The intersection unit on triangle `triangle` of instance `instance`'s object: the object-space
 * ray moved into unit-triangle space by the triangle's T_delta (two transformation steps), then
 * intersected and accepted as saarcor_dpi_intersect does (fp24 images). */
int saarcor_dpi_core_intersect(unsigned int instance, unsigned int triangle, unsigned int ox,
                               unsigned int oy, unsigned int oz, unsigned int dx, unsigned int dy,
                               unsigned int dz, unsigned int best_t, unsigned int best_instance,
                               unsigned int best_triangle, unsigned int* t, unsigned int* u,
                               unsigned int* v, unsigned int* c, int* inside, int* accept);

#ifdef __cplusplus
}
#endif

#endif
