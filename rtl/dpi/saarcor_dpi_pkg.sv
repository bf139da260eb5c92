// The model's DPI-C reference for SystemVerilog testbenches (docs/dpi.md): the imports of
// libsaarcor_dpi.so (rtl/dpi/saarcor_dpi.h, a plain C ABI). Standard DPI-C only, nothing specific to
// one simulator. Encodings are `int unsigned` (the low 1 + E + M bits), flags `int` 0/1; every
// function returns 0 (SAARCOR_DPI_OK) or -1 (SAARCOR_DPI_ERROR), and then last_error() says why.
package saarcor_dpi_pkg;

  localparam int SAARCOR_DPI_OK = 0;
  localparam int SAARCOR_DPI_ERROR = -1;
  localparam int SAARCOR_DPI_VERSION = 1;  // saarcor_dpi_version() of a matching library
  localparam int unsigned SAARCOR_NO_HIT = 32'hffff_ffff;  // instance/triangle of a miss

  import "DPI-C" function string saarcor_dpi_last_error();
  import "DPI-C" function int saarcor_dpi_version();

  // ---- float operators, any format eEmM, round "rne"|"rtz", subnormals "flush"|"keep";
  // op: add sub mul div sqrt min max lt le eq
  import "DPI-C" function int saarcor_dpi_fp_op(
      input string op, input int exp_bits, input int man_bits, input string round,
      input string subnormals, input int unsigned a, input int unsigned b,
      output int unsigned result);
  import "DPI-C" function int saarcor_dpi_fp_from_real(
      input real value, input int exp_bits, input int man_bits, input string round,
      input string subnormals, output int unsigned bits);
  import "DPI-C" function int saarcor_dpi_fp_to_real(
      input int unsigned bits, input int exp_bits, input int man_bits, input string subnormals,
      output real value);

  // ---- the unit datapaths in fp24 (e7m16), the FP units' mode as above
  import "DPI-C" function int saarcor_dpi_traversal_lane(
      input string round, input string subnormals, input int unsigned split,
      input int unsigned o_axis, input int unsigned d_axis, input int unsigned tn,
      input int unsigned tf, output int go_near, output int go_far, output int unsigned near_tf,
      output int unsigned far_tn);
  import "DPI-C" function int saarcor_dpi_transform_step(
      input string round, input string subnormals, input int unsigned m00, input int unsigned m01,
      input int unsigned m02, input int unsigned t0, input int unsigned m10,
      input int unsigned m11, input int unsigned m12, input int unsigned t1,
      input int unsigned m20, input int unsigned m21, input int unsigned m22,
      input int unsigned t2, input int unsigned x, input int unsigned y, input int unsigned z,
      input int translate, output int unsigned rx, output int unsigned ry,
      output int unsigned rz);
  import "DPI-C" function int saarcor_dpi_intersect(
      input string round, input string subnormals, input int unsigned ox, input int unsigned oy,
      input int unsigned oz, input int unsigned dx, input int unsigned dy, input int unsigned dz,
      input int unsigned instance_id, input int unsigned triangle_id, input int unsigned best_t,
      input int unsigned best_instance, input int unsigned best_triangle, output int unsigned t,
      output int unsigned u, output int unsigned v, output int unsigned c, output int hit_inside,
      output int accept);

  // ---- the core on a memory image file (`saarcor scene SCENE --write-image FILE`)
  import "DPI-C" function int saarcor_dpi_load_image(input string path);
  import "DPI-C" function int saarcor_dpi_unload_image();
  import "DPI-C" function int saarcor_dpi_image_info(
      output int width, output int height, output int exp_bits, output int man_bits,
      output int instances);
  import "DPI-C" function int saarcor_dpi_trace_pixel(
      input int x, input int y, input int packet, output int unsigned instance_id,
      output int unsigned triangle_id, output int unsigned t, output int unsigned u,
      output int unsigned v);
  import "DPI-C" function int saarcor_dpi_core_transform(
      input int unsigned row, input int translate, input int unsigned x, input int unsigned y,
      input int unsigned z, output int unsigned rx, output int unsigned ry,
      output int unsigned rz);
  import "DPI-C" function int saarcor_dpi_core_traversal(
      input int unsigned node, input int unsigned ox, input int unsigned oy, input int unsigned oz,
      input int unsigned dx, input int unsigned dy, input int unsigned dz, input int unsigned tn,
      input int unsigned tf, output int axis, output int go_near, output int go_far,
      output int unsigned near_tf, output int unsigned far_tn);
  import "DPI-C" function int saarcor_dpi_core_intersect(
      input int unsigned instance_id, input int unsigned triangle_id, input int unsigned ox,
      input int unsigned oy, input int unsigned oz, input int unsigned dx, input int unsigned dy,
      input int unsigned dz, input int unsigned best_t, input int unsigned best_instance,
      input int unsigned best_triangle, output int unsigned t, output int unsigned u,
      output int unsigned v, output int unsigned c, output int hit_inside, output int accept);

endpackage
