// The transformation unit of a DynRTP with its thread machinery (paper sections 2.2, 2.3 and 3.1,
// Figure 2 paths a, b, d and e; units/transformation_step.h, units/transformation.cpp; D25, D30,
// D31, D32): the thread machinery of rtl/unit_threads.sv around the 9-mul, 9-add step of
// rtl/transform_unit.sv.
//   Arrival (units/boundary_transformation.h), path d first (D25): a list entry, an object (the
//   instance's six rows: the matrix, the header with the bottom tree's root and the triangles'
//   row base, the object box) or a triangle (T_delta's three rows), with its mask; path a: a
//   packet to generate, per lane its matrix T and R' (the lanes' rays start cleared, as the
//   model's load clears them). The rows are fetched through the row cache at accept, one request
//   a cycle (D32); a response names its row by its address.
//   Step: n + 1 issue cycles for a packet whose rays share an origin (the origin once, with lane
//   0's inputs, then one direction a ray), else 2n (origin and direction a ray), whatever the
//   mask (D30, D31); one vector a cycle into the datapath. A result is written DEPTH cycles later
//   into the thread's rays (generation: the world ray, which is also the current one; an object:
//   the object-space ray, which starts as the world ray at the object's issue; a triangle: the
//   unit-triangle-space ray) for the lanes that entered; an origin also for the others, the
//   shared one or +0 (the model's rule).
//   Output: DEPTH cycles after the last step (its result forwarded), to the traversal unit (a
//   level starts: after ray generation, or an object, with its box and root), the intersection
//   unit (a triangle), or the RGS (generated shadow rays). A triangle carries on to the
//   intersection unit what it needs beside the rays (units/boundary_intersection.h): the list's
//   rays and last as path d brought them, the object the thread entered (its last object entry)
//   and the triangle's id; a level start (to the traversal unit, or the RGS for shadow rays)
//   carries the packet's shadow flag from path a. A field a destination does not carry is 0.
module transformation_threads #(
    parameter int THREADS = 16,
    parameter int P       = 4,
    parameter int LAT_ADD = 3,
    parameter int LAT_MUL = 3,
    parameter bit FAULT_N_PLUS_ONE_OFF = 1'b0,  // tests only: 2n steps for a shared origin too
    parameter bit FAULT_ROW_ORDER = 1'b0,  // tests only: an entry's second and third rows swapped
    parameter int TW      = THREADS > 1 ? $clog2(THREADS) : 1
) (
    input  logic                 clk,
    input  logic                 rst,
    input  logic [31:0]          instance_row_base,  // the frame register
    // Path d (from the list unit): kind 0 an object, 1 a triangle; the entry id; the rays; the
    // level's rays still in the list and whether the entry was its last (D49).
    input  logic                 d_valid,
    input  logic [TW-1:0]        d_thread,
    input  logic                 d_kind,
    input  logic [31:0]          d_entry,
    input  logic [P-1:0]         d_mask,
    input  logic [P-1:0]         d_list,
    input  logic                 d_last,
    // Path a (from the RGS): a packet. Lane i's T is a_t[i*288 +: 288] (m_r0, m_r1, m_r2, t_r for
    // r = 0, 1, 2, 24 bits each, lowest first), R'o a_ro[i*72 +: 72] (x lowest), R'd likewise.
    input  logic                 a_valid,
    input  logic [TW-1:0]        a_thread,
    input  logic                 a_shadow,
    input  logic                 a_shared,
    input  logic [P-1:0]         a_valid_lanes,
    input  logic [P*288-1:0]     a_t,
    input  logic [P*72-1:0]      a_ro,
    input  logic [P*72-1:0]      a_rd,
    // Row cache: one request a cycle; a response is one row (fp24: four fields in three words).
    output logic                 req_valid,
    output logic [31:0]          req_item,
    output logic [TW-1:0]        req_thread,
    input  logic                 req_ready,
    input  logic                 resp_valid,
    input  logic [TW-1:0]        resp_thread,
    input  logic [31:0]          resp_item,
    input  logic [95:0]          resp_words,
    // Output: dest 0 traversal, 1 intersection, 2 RGS; per lane O, D (out_o[i*72 +: 72]).
    output logic                 out_valid,
    output logic [TW-1:0]        out_thread,
    output logic [1:0]           out_dest,
    output logic                 out_level,
    output logic                 out_shared,
    output logic [P-1:0]         out_mask,
    output logic [31:0]          out_root,
    output logic [P*72-1:0]      out_o,
    output logic [P*72-1:0]      out_d,
    output logic [71:0]          out_lo,
    output logic [71:0]          out_hi,
    // Dest 1 (path e): list, last, the object the thread entered and the triangle; else 0.
    output logic [P-1:0]         out_list,
    output logic                 out_last,
    output logic [31:0]          out_instance,
    output logic [31:0]          out_triangle,
    // Dest 0 and 2 (a level starts): the packet's shadow flag; else 0.
    output logic                 out_shadow
);
  localparam int W = 24;
  localparam int DEPTH = LAT_MUL + 2 * LAT_ADD;
  localparam int LW = P > 1 ? $clog2(P) : 1;
  localparam int SW = $clog2(2 * P + 1);
  localparam int OpGen = 0, OpObject = 1, OpTriangle = 2;

  // ---- per-thread state ------------------------------------------------------------------------
  logic [1:0]    op_r[THREADS];
  logic [31:0]   entry_r[THREADS];
  logic [P-1:0]  mask_r[THREADS];
  logic [P-1:0]  list_r[THREADS];                      // path d's list and last
  logic          last_r[THREADS];
  logic [31:0]   inst_r[THREADS];                      // the object the thread entered
  logic          shadow_r[THREADS], shared_r[THREADS];
  logic [287:0]  gt_r[THREADS][P];                     // ray generation's T per lane
  logic [71:0]   gro_r[THREADS][P], grd_r[THREADS][P];  // and R'
  logic [287:0]  mat_r[THREADS];                       // the entry's matrix (rows 0-2)
  logic [31:0]   root_r[THREADS], trb_r[THREADS];       // the object's header row
  logic [71:0]   lo_r[THREADS], hi_r[THREADS];          // the object's box
  logic [31:0]   first_r[THREADS];                     // the entry's first row
  // The rays: world (generated), current (object space), tri (unit-triangle space).
  logic [71:0]   wo[THREADS][P], wd[THREADS][P], co[THREADS][P], cd[THREADS][P];
  logic [71:0]   to[THREADS][P], td[THREADS][P];

  // ---- the thread machinery --------------------------------------------------------------------
  logic acc_valid, iss_valid;
  logic [TW-1:0] acc_thread, iss_thread;
  logic [31:0] acc_first;
  logic [2:0] acc_count;
  // The row requested (the injected fault, tests only: while fetching, i.e. not in the accept's
  // cycle, the entry's second row is requested third and its third second).
  logic [31:0] fetch_item, fetch_k;
  assign fetch_k = fetch_item - first_r[req_thread];
  always_comb begin
    req_item = fetch_item;
    if (FAULT_ROW_ORDER && !acc_valid && fetch_k == 32'd1) req_item = fetch_item + 32'd1;
    if (FAULT_ROW_ORDER && !acc_valid && fetch_k == 32'd2) req_item = fetch_item - 32'd1;
  end
  // The first row: 6 or 3 rows an entry, as shifts and adds (a constant multiply would take
  // multiplier blocks on the FPGA).
  logic [31:0] acc_entry;
  assign acc_entry = entry_r[acc_thread];
  always_comb begin
    acc_first = '0;
    acc_count = '0;
    if (op_r[acc_thread] == 2'(OpObject)) begin
      acc_first = instance_row_base + (acc_entry << 2) + (acc_entry << 1);
      acc_count = 3'd6;
    end else if (op_r[acc_thread] == 2'(OpTriangle)) begin
      acc_first = trb_r[acc_thread] + (acc_entry << 1) + acc_entry;
      acc_count = 3'd3;
    end
  end
  logic [SW-1:0] steps;
  assign steps = shared_r[iss_thread] && !FAULT_N_PLUS_ONE_OFF ? SW'(P + 1) : SW'(2 * P);
  /* verilator lint_off UNUSEDSIGNAL */
  logic [0:0] out_payload;
  /* verilator lint_on UNUSEDSIGNAL */
  unit_threads #(
      .THREADS(THREADS), .INPUTS(2), .DEPTH(DEPTH), .PW(1), .IW(32), .CW(3), .SW(SW)
  ) threads (
      .clk, .rst, .in_valid({a_valid, d_valid}), .in_thread({a_thread, d_thread}),
      .acc_valid, .acc_thread, .acc_first, .acc_count,
      .req_valid, .req_item(fetch_item), .req_thread, .req_ready, .resp_valid, .resp_thread,
      .iss_valid, .iss_thread, .iss_steps(steps), .iss_chain(1'b0), .iss_payload(1'b0),
      .out_valid, .out_thread, .out_payload, .out_ready(1'b1));
  /* verilator lint_off UNUSEDSIGNAL */
  logic unused_acc;
  assign unused_acc = acc_valid;
  /* verilator lint_on UNUSEDSIGNAL */

  // ---- one vector a cycle into the datapath ----------------------------------------------------
  logic busy;
  logic [TW-1:0] seq_thread;
  logic [SW-1:0] seq_step, seq_steps;
  logic [TW-1:0] f_thread;
  logic [SW-1:0] f_step;
  assign f_thread = iss_valid ? iss_thread : seq_thread;
  assign f_step = iss_valid ? '0 : seq_step;
  // Step k: shared origin, k = 0 the origin (lane 0's inputs), k >= 1 lane k - 1's direction;
  // else k = 2i lane i's origin, 2i + 1 its direction. (The fault's extra steps feed nothing.)
  logic f_shared, f_origin, feed;
  logic [LW-1:0] f_lane;
  always_comb begin
    f_shared = shared_r[f_thread];
    if (f_shared) begin
      f_origin = f_step == '0;
      f_lane = f_origin ? '0 : LW'(f_step - SW'(1));
      feed = (iss_valid || busy) && 32'(f_step) <= P;
    end else begin
      f_origin = !f_step[0];
      f_lane = LW'(f_step >> 1);
      feed = iss_valid || busy;
    end
  end
  logic [1:0] f_op;
  logic [287:0] f_m;
  logic [71:0] f_v;
  always_comb begin
    f_op = op_r[f_thread];
    case (f_op)
      2'(OpGen): begin
        f_m = gt_r[f_thread][f_lane];
        f_v = f_origin ? gro_r[f_thread][f_lane] : grd_r[f_thread][f_lane];
      end
      2'(OpObject): begin
        f_m = mat_r[f_thread];
        f_v = f_origin ? wo[f_thread][f_lane] : wd[f_thread][f_lane];
      end
      default: begin
        f_m = mat_r[f_thread];
        f_v = f_origin ? co[f_thread][f_lane] : cd[f_thread][f_lane];
      end
    endcase
  end
  logic dp_valid;
  logic [W-1:0] rx, ry, rz;
  transform_unit #(.LAT_ADD(LAT_ADD), .LAT_MUL(LAT_MUL)) datapath (
      .clk, .rst, .in_valid(feed),
      .m00(f_m[0+:W]), .m01(f_m[W+:W]), .m02(f_m[2*W+:W]), .t0(f_m[3*W+:W]),
      .m10(f_m[4*W+:W]), .m11(f_m[5*W+:W]), .m12(f_m[6*W+:W]), .t1(f_m[7*W+:W]),
      .m20(f_m[8*W+:W]), .m21(f_m[9*W+:W]), .m22(f_m[10*W+:W]), .t2(f_m[11*W+:W]),
      .x(f_v[0+:W]), .y(f_v[W+:W]), .z(f_v[2*W+:W]), .translate(f_origin),
      .out_valid(dp_valid), .rx, .ry, .rz);
  logic [TW-1:0] wb_thread;
  logic [LW-1:0] wb_lane;
  logic wb_origin, wb_shared;
  logic [1:0] wb_op;
  fp_stage #(.W(TW + LW + 4), .N(DEPTH)) u_tag (
      .clk, .d({f_thread, f_lane, f_origin, f_shared, f_op}),
      .q({wb_thread, wb_lane, wb_origin, wb_shared, wb_op}));
  logic [71:0] wb_v;
  assign wb_v = {rz, ry, rx};
  // Per lane: what the writeback gives it (valid) and the value; an origin reaches every lane.
  logic [P-1:0] wb_hit;
  logic [P*72-1:0] wb_val;
  always_comb begin
    for (int i = 0; i < P; i++) begin
      logic entered;
      entered = mask_r[wb_thread][i];
      wb_hit[i] = dp_valid && (wb_origin ? (wb_shared || wb_lane == LW'(i))
                                         : wb_lane == LW'(i) && entered);
      wb_val[i*72+:72] = wb_origin && !wb_shared && !entered ? 72'd0 : wb_v;
    end
  end

  // ---- output: the leaving thread's rays, the last step's result forwarded ---------------------
  logic [1:0] o_op;
  assign o_op = op_r[out_thread];
  always_comb begin
    for (int i = 0; i < P; i++) begin
      logic fwd;
      logic [71:0] o, d;
      fwd = wb_hit[i] && wb_thread == out_thread;
      case (o_op)
        2'(OpGen): begin
          o = wo[out_thread][i];
          d = wd[out_thread][i];
        end
        2'(OpObject): begin
          o = co[out_thread][i];
          d = cd[out_thread][i];
        end
        default: begin
          o = to[out_thread][i];
          d = td[out_thread][i];
        end
      endcase
      out_o[i*72+:72] = fwd && wb_origin ? wb_val[i*72+:72] : o;
      out_d[i*72+:72] = fwd && !wb_origin ? wb_val[i*72+:72] : d;
    end
  end
  assign out_dest = o_op == 2'(OpTriangle) ? 2'd1 : o_op == 2'(OpGen) && shadow_r[out_thread] ?
                    2'd2 : 2'd0;
  assign out_level = o_op == 2'(OpObject);
  assign out_shared = shared_r[out_thread];
  assign out_mask = mask_r[out_thread];
  assign out_root = o_op == 2'(OpObject) ? root_r[out_thread] : 32'd0;
  assign out_lo = o_op == 2'(OpObject) ? lo_r[out_thread] : 72'd0;
  assign out_hi = o_op == 2'(OpObject) ? hi_r[out_thread] : 72'd0;
  assign out_list = o_op == 2'(OpTriangle) ? list_r[out_thread] : '0;
  assign out_last = o_op == 2'(OpTriangle) && last_r[out_thread];
  assign out_instance = o_op == 2'(OpTriangle) ? inst_r[out_thread] : 32'd0;
  assign out_triangle = o_op == 2'(OpTriangle) ? entry_r[out_thread] : 32'd0;
  assign out_shadow = o_op != 2'(OpTriangle) && shadow_r[out_thread];

  // A response's row, unpacked (fp24: the fields at bits 0, 24, 48, 72 of the three words).
  logic [31:0] resp_row;
  assign resp_row = resp_item - first_r[resp_thread];

  always_ff @(posedge clk) begin
    if (rst) begin
      busy <= 1'b0;
    end else begin
      if (iss_valid) begin
        seq_thread <= iss_thread;
        seq_step <= SW'(1);
        seq_steps <= steps;
        busy <= steps > SW'(1);
      end else if (busy) begin
        seq_step <= seq_step + SW'(1);
        busy <= seq_step + SW'(1) < seq_steps;
      end
      // An object step starts from the world rays: a lane it does not transform keeps the world
      // ray as its object-space ray (the model's current = world at every top-level start and
      // when a bottom level ends, the only ways to a top-level list's object).
      if (iss_valid && op_r[iss_thread] == 2'(OpObject))
        for (int i = 0; i < P; i++) begin
          co[iss_thread][i] <= wo[iss_thread][i];
          cd[iss_thread][i] <= wd[iss_thread][i];
        end
      for (int i = 0; i < P; i++)
        if (wb_hit[i]) begin
          if (wb_op == 2'(OpGen) && wb_origin) begin
            wo[wb_thread][i] <= wb_val[i*72+:72];
            co[wb_thread][i] <= wb_val[i*72+:72];
          end else if (wb_op == 2'(OpGen)) begin
            wd[wb_thread][i] <= wb_val[i*72+:72];
            cd[wb_thread][i] <= wb_val[i*72+:72];
          end else if (wb_op == 2'(OpObject) && wb_origin) begin
            co[wb_thread][i] <= wb_val[i*72+:72];
          end else if (wb_op == 2'(OpObject)) begin
            cd[wb_thread][i] <= wb_val[i*72+:72];
          end else if (wb_origin) begin
            to[wb_thread][i] <= wb_val[i*72+:72];
          end else begin
            td[wb_thread][i] <= wb_val[i*72+:72];
          end
        end
      if (acc_valid && acc_count != '0) first_r[acc_thread] <= acc_first;
      if (resp_valid) begin
        case (resp_row)
          32'd0, 32'd1, 32'd2: mat_r[resp_thread][resp_row[1:0]*96+:96] <= resp_words;
          32'd3: begin
            root_r[resp_thread] <= resp_words[31:0];
            trb_r[resp_thread] <= resp_words[63:32];
          end
          32'd4: lo_r[resp_thread] <= resp_words[71:0];
          default: hi_r[resp_thread] <= resp_words[71:0];
        endcase
      end
      if (d_valid) begin
        op_r[d_thread] <= d_kind ? 2'(OpTriangle) : 2'(OpObject);
        entry_r[d_thread] <= d_entry;
        mask_r[d_thread] <= d_mask;
        list_r[d_thread] <= d_list;
        last_r[d_thread] <= d_last;
        if (!d_kind) inst_r[d_thread] <= d_entry;
      end
      if (a_valid) begin
        op_r[a_thread] <= 2'(OpGen);
        mask_r[a_thread] <= a_valid_lanes;
        shadow_r[a_thread] <= a_shadow;
        shared_r[a_thread] <= a_shared;
        for (int i = 0; i < P; i++) begin
          gt_r[a_thread][i] <= a_t[i*288+:288];
          gro_r[a_thread][i] <= a_ro[i*72+:72];
          grd_r[a_thread][i] <= a_rd[i*72+:72];
          wo[a_thread][i] <= '0;
          wd[a_thread][i] <= '0;
          co[a_thread][i] <= '0;
          cd[a_thread][i] <= '0;
          to[a_thread][i] <= '0;
          td[a_thread][i] <= '0;
        end
      end
    end
  end
endmodule
