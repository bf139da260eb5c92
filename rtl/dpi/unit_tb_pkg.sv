// The transactions, the stimulus and the scoreboard of the DPI-C unit testbench
// (unit_scoreboard_tb.sv, docs/dpi.md), UVM-style without UVM: a transaction carries one vector's
// inputs and the reference's prediction through saarcor_dpi_pkg (the model's own datapath
// functions in libsaarcor_dpi.so); the scoreboard pairs the RTL's outputs, in order, with the
// predictions and names the vector of every difference.
//
// (Verilator's lint does not follow class members written and read through handles, and wants one
// declaration per file: both checks are off in this file only.)
/* verilator lint_off UNDRIVEN */
/* verilator lint_off UNUSEDSIGNAL */
/* verilator lint_off DECLFILENAME */
package unit_tb_pkg;
  import saarcor_dpi_pkg::*;

  // A real rounded into fp24 (nearest even, subnormals flushed: the prototype's units).
  function automatic int unsigned fp24(input real value);
    int unsigned bits;
    if (saarcor_dpi_fp_from_real(value, 7, 16, "rne", "flush", bits) != SAARCOR_DPI_OK)
      $fatal(1, "saarcor_dpi_fp_from_real: %s", saarcor_dpi_last_error());
    return bits;
  endfunction

  // A uniform real in [lo, hi) on a 2^-16 grid.
  function automatic real uniform(input real lo, input real hi);
    return lo + (hi - lo) * real'($urandom_range(65535)) / 65536.0;
  endfunction

  // An operand: mostly values in [lo, hi), sometimes a raw 24-bit pattern (NaN, inf, zero,
  // subnormal and huge encodings included) or a signed zero.
  function automatic int unsigned operand(input real lo, input real hi);
    int unsigned pick = $urandom_range(15);
    if (pick == 0) return $urandom & 32'hff_ffff;
    if (pick == 1) return ($urandom & 1) << 23;
    return fp24(uniform(lo, hi));
  endfunction

  // ---- intersection unit: ox oy oz dx dy dz + ids and the ray's best hit -> t u v c inside accept
  class isect_txn;
    int unsigned index;
    int unsigned ox, oy, oz, dx, dy, dz, instance_id, triangle_id, best_t, best_instance;
    int unsigned best_triangle;
    int unsigned t, u, v, c;
    int hit_inside, accept;

    function string inputs();
      return {$sformatf("ox=%06x oy=%06x oz=%06x dx=%06x dy=%06x dz=%06x", ox, oy, oz, dx, dy, dz),
              $sformatf(" instance=%0d triangle=%0d best_t=%06x best_instance=%0d", instance_id,
                        triangle_id, best_t, best_instance),
              $sformatf(" best_triangle=%0d", best_triangle)};
    endfunction

    function void predict();
      if (saarcor_dpi_intersect("rne", "flush", ox, oy, oz, dx, dy, dz, instance_id, triangle_id,
                                best_t, best_instance, best_triangle, t, u, v, c, hit_inside,
                                accept) != SAARCOR_DPI_OK)
        $fatal(1, "intersection vector %0d: %s", index, saarcor_dpi_last_error());
    endfunction
  endclass

  // ---- transformation unit: 12 matrix entries, x y z, translate -> rx ry rz
  class xf_txn;
    int unsigned index;
    int unsigned m[12];  // row r = m[4r] m[4r+1] m[4r+2] t_r = m[4r+3]
    int unsigned x, y, z;
    int translate;
    int unsigned rx, ry, rz;

    function string inputs();
      string s = "";
      for (int k = 0; k < 12; k++) begin
        string name = k % 4 == 3 ? $sformatf("t%0d", k / 4) : $sformatf("m%0d%0d", k / 4, k % 4);
        s = {s, $sformatf("%s=%06x ", name, m[k])};
      end
      return {s, $sformatf("x=%06x y=%06x z=%06x translate=%0d", x, y, z, translate)};
    endfunction

    function void predict();
      if (saarcor_dpi_transform_step("rne", "flush", m[0], m[1], m[2], m[3], m[4], m[5], m[6],
                                     m[7], m[8], m[9], m[10], m[11], x, y, z, translate, rx, ry,
                                     rz) != SAARCOR_DPI_OK)
        $fatal(1, "transformation vector %0d: %s", index, saarcor_dpi_last_error());
    endfunction
  endclass

  // The stimulus: rays in unit-triangle space around the unit triangle, a third of them aimed at a
  // point inside it; best hits that are closer, farther, absent or tied in t (the id tie rule);
  // and the corner cases no random draw finds: u + v exactly 1, D'z = +-0.
  class sequencer;
    int unsigned made_isect = 0, made_xf = 0;

    function isect_txn next_isect();
      isect_txn tr = new;
      int unsigned k = made_isect;
      tr.index = made_isect++;
      tr.ox = operand(-0.5, 1.5);
      tr.oy = operand(-0.5, 1.5);
      tr.oz = operand(-2.0, 2.0);
      tr.dx = operand(-1.0, 1.0);
      tr.dy = operand(-1.0, 1.0);
      tr.dz = operand(-1.0, 1.0);
      if (k % 3 == 1) begin
        // aimed at a point (a, b) of the triangle from t in (0, 3] away: o = (a, b, 0) - t d
        real a = uniform(0.0, 1.0), b = uniform(0.0, 1.0), t = uniform(0.01, 3.0);
        real d[3] = '{uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0)};
        if (a + b > 1.0) begin
          a = 1.0 - a;
          b = 1.0 - b;
        end
        {tr.dx, tr.dy, tr.dz} = {fp24(d[0]), fp24(d[1]), fp24(d[2])};
        {tr.ox, tr.oy, tr.oz} = {fp24(a - t * d[0]), fp24(b - t * d[1]), fp24(-t * d[2])};
      end
      if (k % 16 == 5) begin
        // o = (a, 1 - a, -1), d = (0, 0, 1): t = 1, u = a, v = 1 - a, u + v = 1 exactly, the
        // edge the acceptance keeps (u + v <= 1)
        real a = 0.25 * real'($urandom_range(4));
        tr.ox = fp24(a);
        tr.oy = fp24(1.0 - a);
        tr.oz = fp24(-1.0);
        tr.dx = 0;
        tr.dy = 0;
        tr.dz = fp24(1.0);
      end
      if (k % 16 == 9) tr.dz = (k % 32 == 9) ? 0 : 32'h80_0000;  // D'z = +0 / -0
      tr.instance_id = $urandom_range(3);
      tr.triangle_id = $urandom_range(3);
      tr.best_instance = $urandom_range(3);
      tr.best_triangle = $urandom_range(3);
      case (k % 4)
        0: tr.best_t = 32'h7f_0000;  // +inf: no hit yet
        1: tr.best_t = fp24(uniform(0.0, 3.0));
        default: tr.best_t = 0;  // replaced by the candidate's own t below: a tie
      endcase
      tr.best_instance = (k % 4 == 0) ? SAARCOR_NO_HIT : tr.best_instance;
      tr.best_triangle = (k % 4 == 0) ? SAARCOR_NO_HIT : tr.best_triangle;
      tr.predict();
      if (k % 4 >= 2) begin
        tr.best_t = tr.t & 32'h7f_ffff;  // t's magnitude (the acceptance reads magnitudes)
        tr.predict();
      end
      return tr;
    endfunction

    function xf_txn next_xf();
      xf_txn tr = new;
      tr.index = made_xf++;
      foreach (tr.m[i]) tr.m[i] = operand(-4.0, 4.0);
      tr.x = operand(-8.0, 8.0);
      tr.y = operand(-8.0, 8.0);
      tr.z = operand(-8.0, 8.0);
      tr.translate = int'($urandom_range(1));
      if (tr.index % 8 == 3) begin  // x + (-x): exact cancellation is +0
        tr.m[1] = tr.m[0] ^ 32'h80_0000;
        tr.y = tr.x;
      end
      tr.predict();
      return tr;
    endfunction
  endclass

  // Expected transactions in issue order; each RTL output is checked against the oldest. A
  // difference prints one line naming the unit, the vector's index and inputs, the field, the
  // RTL's and the model's values.
  class scoreboard;
    isect_txn isect_expected[$];
    xf_txn xf_expected[$];
    int unsigned checked_isect = 0, checked_xf = 0, mismatches = 0;
    int unsigned n_inside = 0, n_accepted = 0;  // how many checked vectors the model finds inside / accepts

    function void field(string unit, int unsigned index, string inputs, string name,
                        int unsigned rtl, int unsigned model);
      if (rtl == model) return;
      mismatches++;
      $display("MISMATCH %s vector %0d: %s rtl=%06x model=%06x (%s)", unit, index, name, rtl,
               model, inputs);
    endfunction

    function void check_isect(int unsigned t, int unsigned u, int unsigned v, int unsigned c,
                              int hit_inside, int accept);
      isect_txn e;
      if (isect_expected.size() == 0) begin
        mismatches++;
        $display("MISMATCH intersection: an output with no vector in flight");
        return;
      end
      e = isect_expected.pop_front();
      checked_isect++;
      n_inside += e.hit_inside;
      n_accepted += e.accept;
      field("intersection", e.index, e.inputs(), "t", t, e.t);
      field("intersection", e.index, e.inputs(), "u", u, e.u);
      field("intersection", e.index, e.inputs(), "v", v, e.v);
      field("intersection", e.index, e.inputs(), "c", c, e.c);
      field("intersection", e.index, e.inputs(), "inside", hit_inside, e.hit_inside);
      field("intersection", e.index, e.inputs(), "accept", accept, e.accept);
    endfunction

    function void check_xf(int unsigned rx, int unsigned ry, int unsigned rz);
      xf_txn e;
      if (xf_expected.size() == 0) begin
        mismatches++;
        $display("MISMATCH transformation: an output with no vector in flight");
        return;
      end
      e = xf_expected.pop_front();
      checked_xf++;
      field("transformation", e.index, e.inputs(), "rx", rx, e.rx);
      field("transformation", e.index, e.inputs(), "ry", ry, e.ry);
      field("transformation", e.index, e.inputs(), "rz", rz, e.rz);
    endfunction
  endclass
endpackage
