// The traversal unit of the DynRTP (paper section 3.1; units/traversal_step.h TraversalStep;
// decisions D26 stack, D27 sign groups, D29 box clip): the issue slot, the pipeline and the
// per-thread state behind it. P lanes of `traversal_unit` (1 add, 1 div, 2 cmp each) take one
// request per cycle:
//   step  one kd-node of the packet: early termination at node entry (t_best < tn, a compare per
//         lane at issue), the lanes' near/far decision, the shared near child (the direction sign
//         of the first active lane, D27), the push of the far child, the leaf handed to the list
//         unit (path c), and the pop when no child is left;
//   clip  the faces of the level's box (D29): the chain issues one face per cycle, six, or the
//         three exit faces when every origin is inside the box; each face's t = (plane - O) / D
//         comes out of the lanes' adder and divider and folds into the clipped segment (max for an
//         entry face, min for an exit face, in face order); the last face forms the sign groups and
//         starts the first (D27);
//   pop   the end of a leaf's list (hw-interface.md: the thread passes through the unit to pop).
// The thread leaves DEPTH = LAT_ADD + LAT_DIV + LAT_CMP cycles after its (last) issue, the cycle
// model's traversal_depth(). The stack (STACK entries per thread, shared by both levels) is a
// memory read one entry per cycle: an entry popped without drops leaves in that cycle, as in the
// model; each dropped entry (its rays have all hit something nearer, or are done) costs a cycle,
// delivered on the second output port (docs/hw-interface.md "Where the model cannot be built").
//
// Per-thread ray data as the hardware keeps it (D43): per lane the world ray, the object ray, the
// segment (tn, tf), the level's clipped segment, t_best and done; per thread the node, the mask,
// the level, the sign groups and the stack. The hit-update port writes t_best and done after each
// intersection.
//
// Test-only faults (0 in every real build): FAULT_POP_OFF pops the entry below the top;
// FAULT_SHORT makes the pipeline one cycle short (the lanes' compare stage becomes a wire).
module traversal_ctrl #(
    parameter int E             = 7,
    parameter int M             = 16,
    parameter bit RNE           = 1'b1,
    parameter bit FLUSH         = 1'b1,
    parameter int LAT_ADD       = 3,
    parameter int LAT_DIV       = 8,
    parameter int LAT_CMP       = 1,
    parameter int P             = 4,
    parameter int THREADS       = 64,
    parameter int STACK         = 64,
    parameter int NODE_W        = 28,
    parameter bit SKIP_EMPTY    = 1'b1,
    parameter bit EXIT_ONLY     = 1'b1,
    parameter bit FAULT_POP_OFF = 1'b0,
    parameter bit FAULT_SHORT   = 1'b0,
    localparam int W            = E + M + 1,
    localparam int TW           = THREADS > 1 ? $clog2(THREADS) : 1,
    localparam int LW           = P > 1 ? $clog2(P) : 1,
    localparam int SW           = $clog2(STACK + 1)
) (
    input  logic              clk,
    input  logic              rst,
    // Frame registers: the scene box (x, y, z from bit 0) and the top-level root.
    input  logic [   3*W-1:0] scene_lo,
    input  logic [   3*W-1:0] scene_hi,
    input  logic [NODE_W-1:0] top_root,
    // Level start with its rays (path b from the transformation unit: port 0; RGS -> traversal:
    // port 1), all P lanes in the cycle the thread is pushed: the top level's world rays with
    // t_best, valid and done, or (ld_bottom) an object's rays with its box (rows 4-5 of the
    // instance record), root and entry mask. The bottom level reads t_best from the unit's copy
    // (the hit updates keep it).
    input  logic [1:0]                  ld_valid,
    input  logic [1:0][TW-1:0]          ld_thread,
    input  logic [1:0]                  ld_bottom,
    input  logic [1:0]                  ld_shadow,
    input  logic [1:0][P-1:0]           ld_mask,
    input  logic [1:0][3*W-1:0]         ld_lo,
    input  logic [1:0][3*W-1:0]         ld_hi,
    input  logic [1:0][NODE_W-1:0]      ld_root,
    input  logic [1:0][P-1:0][3*W-1:0]  ld_o,
    input  logic [1:0][P-1:0][3*W-1:0]  ld_d,
    input  logic [1:0][P-1:0][W-1:0]    ld_tbest,
    input  logic [1:0][P-1:0]           ld_lane_valid,
    input  logic [1:0][P-1:0]           ld_done,
    // Hit update (the intersection unit's hits, as the thread leaves it): t_best and done of
    // every lane.
    input  logic                        hu_valid,
    input  logic [TW-1:0]               hu_thread,
    input  logic [P-1:0][W-1:0]         hu_tbest,
    input  logic [P-1:0]                hu_done,
    // The thread's next request (what the accept stage fetches): a clip face or a node.
    input  logic [    TW-1:0] rq_thread,
    output logic              rq_clip,
    output logic [       2:0] rq_face,
    output logic [NODE_W-1:0] rq_node,
    output logic [     P-1:0] rq_mask,
    // Issue: kind 0 node step (with the node's two words), 1 clip (the whole chain), 2 pop.
    input  logic              is_valid,
    input  logic [    TW-1:0] is_thread,
    input  logic [       1:0] is_kind,
    input  logic [      31:0] is_w0,
    input  logic [      31:0] is_w1,
    output logic              is_busy,
    output logic              is_chain,  // the face issued now is followed by another (a chain)
    // Leaving threads. dest 0: own loop (node, mask: the next node), 1: a leaf's list to the list
    // unit (first, end, mask), 2: back to the top level's list (the object is done), 3: the RGS
    // (path g); level: the level of the request. Fields a destination does not carry are 0.
    // Port 2 carries the pops that dropped entries (node, mask, level).
    output logic              out_valid,
    output logic [    TW-1:0] out_thread,
    output logic [       1:0] out_dest,
    output logic [NODE_W-1:0] out_node,
    output logic [      31:0] out_first,
    output logic [      31:0] out_end,
    output logic [     P-1:0] out_mask,
    output logic              out_level,
    output logic              out2_valid,
    output logic [    TW-1:0] out2_thread,
    output logic [       1:0] out2_dest,
    output logic [NODE_W-1:0] out2_node,
    output logic [     P-1:0] out2_mask,
    output logic              out2_level,
    output logic              overflow,
    // Debug read of one lane's state (the testbench compares it with the model).
    input  logic [    TW-1:0] dbg_thread,
    input  logic [    LW-1:0] dbg_lane,
    output logic [     W-1:0] dbg_tn,
    output logic [     W-1:0] dbg_tf,
    output logic [     W-1:0] dbg_ctn,
    output logic [     W-1:0] dbg_ctf,
    output logic [    SW-1:0] dbg_size,
    output logic              dbg_level
);
  localparam int LatCmp = FAULT_SHORT ? LAT_CMP - 1 : LAT_CMP;
  localparam int Depth = LAT_ADD + LAT_DIV + LatCmp;
  localparam int Entries = THREADS * STACK;
  localparam int EW = $clog2(Entries);
  localparam logic [W-1:0] QNaN = {1'b0, {E{1'b1}}, 1'b1, {(M - 1) {1'b0}}};
  localparam logic [W-1:0] PosInf = {1'b0, {E{1'b1}}, {M{1'b0}}};
  localparam logic [1:0] KClip = 2'd1, KPop = 2'd2;  // 0: a node step
  localparam logic [1:0] DLoop = 2'd0, DLeaf = 2'd1, DResume = 2'd2, DRgs = 2'd3;

  // ---- per-thread state (memories indexed by thread id) -----------------------------------
  // (Rays, t_best, the clipped segment and the box are packed per thread, as the load ports carry
  // them: a level start writes each in one piece.)
  logic [P-1:0][2:0][W-1:0] wo[THREADS], wd[THREADS], oo[THREADS], od[THREADS];
  logic [W-1:0] tn_r[THREADS][P], tf_r[THREADS][P];
  logic [P-1:0][W-1:0] ctn_r[THREADS], ctf_r[THREADS], tbest_r[THREADS];
  logic [P-1:0] done_r[THREADS];
  logic level_r[THREADS], shadow_r[THREADS], stride2_r[THREADS];
  logic [2:0] face_r[THREADS];
  logic [NODE_W-1:0] node_r[THREADS], root_r[THREADS];
  logic [P-1:0] mask_r[THREADS], cmask_r[THREADS];
  logic [2:0][W-1:0] blo_r[THREADS], bhi_r[THREADS];
  logic [P-1:0] groups_r[THREADS][8], tgroups_r[THREADS][8];
  logic [3:0] ngroups_r[THREADS], group_r[THREADS], tngroups_r[THREADS], tgroup_r[THREADS];
  logic [SW-1:0] size_r[THREADS], base_r[THREADS], tbase_r[THREADS];
  // The stack: per entry the node, the mask and per lane the far tn and the tf.
  logic [NODE_W-1:0] st_node_m[Entries];
  logic [P-1:0] st_mask_m[Entries];
  logic [W-1:0] st_tn_m[Entries][P], st_tf_m[Entries][P];

  function automatic logic [W-1:0] fld(input logic [3*W-1:0] v, input logic [1:0] k);
    fld = k == 2'd0 ? v[W-1:0] : (k == 2'd1 ? v[2*W-1:W] : v[3*W-1:2*W]);
  endfunction

  // The comparator of the float operators, combinational (fp_cmp_core): a < b, a == b, and the
  // flushed encodings a max/min multiplexer passes on.
  function automatic logic [W:0] flush_mag(input logic [W-1:0] x);
    // {nan, flushed encoding}
    logic [E-1:0] ex;
    ex = x[W-2-:E];
    if (ex == '1) flush_mag = {x[W-2:0] != PosInf[W-2:0], x};
    else if (ex == '0 && FLUSH) flush_mag = {1'b0, x[W-1], {(W - 1) {1'b0}}};
    else flush_mag = {1'b0, x};
  endfunction
  function automatic logic f_nan(input logic [W-1:0] x);
    logic [W:0] f;
    f = flush_mag(x);
    f_nan = f[W];
  endfunction
  function automatic logic f_lt(input logic [W-1:0] a, input logic [W-1:0] b);
    logic [W:0] fa, fb;
    logic sa, sb, zeros;
    fa = flush_mag(a);
    fb = flush_mag(b);
    sa = fa[W-1];
    sb = fb[W-1];
    zeros = (fa[W-2:0] == '0) && (fb[W-2:0] == '0);
    if (fa[W] | fb[W] | zeros) f_lt = 1'b0;
    else if (sa ^ sb) f_lt = sa;
    else f_lt = sa ? (fa[W-2:0] > fb[W-2:0]) : (fa[W-2:0] < fb[W-2:0]);
  endfunction
  function automatic logic [W-1:0] f_flush(input logic [W-1:0] x);
    /* verilator lint_off UNUSEDSIGNAL */
    logic [W:0] f;
    /* verilator lint_on UNUSEDSIGNAL */
    f = flush_mag(x);
    f_flush = f[W-1:0];
  endfunction
  // fixedfloat's max(a, b) = (a < b) ? b : a and min(a, b) = (b < a) ? b : a, flushed.
  function automatic logic [W-1:0] f_max(input logic [W-1:0] a, input logic [W-1:0] b);
    f_max = f_lt(a, b) ? f_flush(b) : f_flush(a);
  endfunction
  function automatic logic [W-1:0] f_min(input logic [W-1:0] a, input logic [W-1:0] b);
    f_min = f_lt(b, a) ? f_flush(b) : f_flush(a);
  endfunction

  // ---- issue: the lanes' operands -----------------------------------------------------------
  // The clip chain: after the first face, the unit issues the remaining faces itself.
  logic cl_busy;
  logic [TW-1:0] cl_thread;
  logic [2:0] cl_face;
  assign is_busy = cl_busy;

  logic in_fire, in_clip, in_pop;
  logic [TW-1:0] in_t;
  logic [2:0] in_face;
  logic [1:0] in_axis;
  assign in_fire = cl_busy | is_valid;
  assign in_t = cl_busy ? cl_thread : is_thread;
  assign in_clip = cl_busy | (is_valid && is_kind == KClip);
  assign in_pop = ~cl_busy & is_valid & (is_kind == KPop);
  assign in_face = cl_busy ? cl_face : face_r[is_thread];
  assign in_axis = in_clip ? 2'(in_face[2:1]) : is_w0[1:0];
  logic in_last_face;
  assign in_last_face = in_clip && ({1'b0, in_face} + (stride2_r[in_t] ? 4'd2 : 4'd1) >= 4'd6);
  assign is_chain = in_clip && !in_last_face;

  logic [W-1:0] l_split[P], l_o[P], l_d[P], l_tn[P], l_tf[P];
  logic [P-1:0] term;
  always_comb begin
    for (int i = 0; i < P; i++) begin
      logic entry, lo_face;
      logic [W-1:0] lo, hi;
      l_o[i] = level_r[in_t] ? oo[in_t][i][in_axis] : wo[in_t][i][in_axis];
      l_d[i] = level_r[in_t] ? od[in_t][i][in_axis] : wd[in_t][i][in_axis];
      lo = level_r[in_t] ? blo_r[in_t][in_axis] : fld(scene_lo, in_axis);
      hi = level_r[in_t] ? bhi_r[in_t][in_axis] : fld(scene_hi, in_axis);
      entry = ~in_face[0];
      lo_face = entry != l_d[i][W-1];
      if (in_clip) begin
        // t = (plane - O) / D comes out as far_tn: tn = NaN makes near true, and a NaN t keeps
        // that NaN, which the max/min fold below passes over (it keeps the old bound).
        l_split[i] = lo_face ? lo : hi;
        l_tn[i] = QNaN;
        l_tf[i] = PosInf;
      end else begin
        l_split[i] = is_w1[W-1:0];
        l_tn[i] = tn_r[in_t][i];
        l_tf[i] = tf_r[in_t][i];
      end
      // Early termination at node entry: t_best < tn leaves the node.
      term[i] = f_lt(tbest_r[in_t][i], tn_r[in_t][i]);
    end
  end

  // Active lanes of a node step; the shared near/far order from the first active lane's sign.
  logic [P-1:0] in_active;
  logic in_neg;
  always_comb begin
    in_active = mask_r[in_t] & ~term;
    if (shadow_r[in_t]) in_active = in_active & ~done_r[in_t];
    if (in_pop || in_clip) in_active = '0;
    in_neg = 1'b0;
    for (int i = P - 1; i >= 0; i--) if (in_active[i]) in_neg = l_d[i][W-1];
  end

  // ---- the pipeline: P lanes and the request's control fields beside them -------------------
  logic [P-1:0] go_near, go_far;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [P-1:0] lane_valid;  // q_valid stands for every lane
  /* verilator lint_on UNUSEDSIGNAL */
  logic [W-1:0] near_tf[P], far_tn[P];
  for (genvar i = 0; i < P; i++) begin : g_lane
    traversal_unit #(
        .E(E), .M(M), .RNE(RNE), .FLUSH(FLUSH), .LAT_ADD(LAT_ADD), .LAT_DIV(LAT_DIV),
        .LAT_CMP(LatCmp)
    ) u_lane (
        .clk, .rst, .in_valid(in_fire), .split(l_split[i]), .o_axis(l_o[i]), .d_axis(l_d[i]),
        .tn(l_tn[i]), .tf(l_tf[i]), .out_valid(lane_valid[i]), .go_near(go_near[i]),
        .go_far(go_far[i]), .near_tf(near_tf[i]), .far_tn(far_tn[i])
    );
  end

  typedef struct packed {
    logic [TW-1:0]     thread;
    logic              clip;
    logic              pop;
    logic [2:0]        face;
    logic              last_face;
    logic              leaf;
    logic [29:0]       count;
    logic [31:0]       first;
    logic [NODE_W-1:0] child;
    logic              empty_l;
    logic              empty_r;
    logic [P-1:0]      active;
    logic              neg;
  } ctl_t;
  ctl_t c_in, c_q;
  localparam int CtlW = TW + 7 + 30 + 32 + NODE_W + 2 + P + 1;  // $bits(ctl_t)
  always_comb begin
    c_in.thread = in_t;
    c_in.clip = in_clip;
    c_in.pop = in_pop;
    c_in.face = in_face;
    c_in.last_face = in_last_face;
    c_in.leaf = is_w0[1:0] == 2'd3;
    c_in.count = is_w0[31:2];
    c_in.first = is_w1;
    c_in.child = is_w0[4+:NODE_W];
    c_in.empty_l = is_w0[2];
    c_in.empty_r = is_w0[3];
    c_in.active = in_active;
    c_in.neg = in_neg;
  end
  logic q_valid;
  fp_stage #(.W(CtlW), .N(Depth)) u_ctl (.clk, .d(c_in), .q(c_q));
  fp_valid #(.N(Depth)) u_qv (.clk, .rst, .d(in_fire), .q(q_valid));

  // ---- the last stage: the step's outcome ----------------------------------------------------
  logic [TW-1:0] qt;
  assign qt = c_q.thread;
  // Clip: the face's t folded into the clipped segment (entry: max, exit: min).
  logic [W-1:0] new_ctn[P], new_ctf[P];
  logic [P-1:0] nonempty;
  logic [P-1:0] by_pattern[8];
  logic [P-1:0] grp[8];
  logic [3:0] ngrp;
  always_comb begin
    for (int i = 0; i < P; i++) begin
      new_ctn[i] = ctn_r[qt][i];
      new_ctf[i] = ctf_r[qt][i];
      // Only the lanes of the clip mask fold (TraversalStep::clip_box); the others keep the values
      // the level's start gave them.
      if (cmask_r[qt][i] && ~c_q.face[0]) new_ctn[i] = f_max(ctn_r[qt][i], far_tn[i]);
      if (cmask_r[qt][i] && c_q.face[0]) new_ctf[i] = f_min(ctf_r[qt][i], far_tn[i]);
      nonempty[i] = cmask_r[qt][i] & ~f_lt(new_ctf[i], new_ctn[i]);
    end
    for (int s = 0; s < 8; s++) begin
      by_pattern[s] = '0;
      grp[s] = '0;
    end
    for (int i = 0; i < P; i++) begin
      logic [2:0] s;
      if (level_r[qt]) s = {od[qt][i][2][W-1], od[qt][i][1][W-1], od[qt][i][0][W-1]};
      else s = {wd[qt][i][2][W-1], wd[qt][i][1][W-1], wd[qt][i][0][W-1]};
      if (nonempty[i]) by_pattern[s][i] = 1'b1;
    end
    ngrp = '0;
    for (int s = 0; s < 8; s++)
      if (by_pattern[s] != '0) begin
        grp[ngrp[2:0]] = by_pattern[s];
        ngrp = ngrp + 4'd1;
      end
  end

  // Node step: near and far children.
  logic [P-1:0] near_m, far_m;
  logic skip_near, skip_far;
  logic [NODE_W-1:0] near_child, far_child;
  always_comb begin
    near_m = go_near & c_q.active;
    far_m = go_far & c_q.active;
    skip_near = SKIP_EMPTY && (c_q.neg ? c_q.empty_r : c_q.empty_l);
    skip_far = SKIP_EMPTY && (c_q.neg ? c_q.empty_l : c_q.empty_r);
    if (skip_near) near_m = '0;
    if (skip_far) far_m = '0;
    near_child = c_q.neg ? c_q.child + 1'b1 : c_q.child;
    far_child = c_q.neg ? c_q.child : c_q.child + 1'b1;
  end

  // What the last stage does with its thread.
  typedef enum logic [2:0] {
    ANone,
    AClipFace,   // a face that is not the last: fold only
    AGroups,     // the last face: fold, form the groups, start the first or end the level
    ALeaf,
    APush,       // both children: push the far one, on to the near one
    ANear,
    AFar,
    APop
  } act_t;
  act_t act;
  always_comb begin
    act = ANone;
    if (q_valid) begin
      if (c_q.clip) act = c_q.last_face ? AGroups : AClipFace;
      else if (c_q.pop || c_q.active == '0) act = APop;
      else if (c_q.leaf) act = c_q.count == '0 ? APop : ALeaf;
      else if (far_m != '0 && near_m != '0) act = APush;
      else if (near_m != '0) act = ANear;
      else if (far_m != '0) act = AFar;
      else act = APop;
    end
  end

  // ---- pops: the stack read one entry per cycle -----------------------------------------------
  // A pop asked for in the last stage is evaluated in that cycle when the pop engine is free; an
  // entry dropped there (or a pop behind another) goes through the queue, one entry per cycle.
  logic [TW-1:0] pq[THREADS];
  logic [TW:0] pq_n;
  logic [TW-1:0] pq_head, pq_tail;
  logic pop_phase2_r[THREADS];
  function automatic logic [TW-1:0] next_slot(input logic [TW-1:0] x);
    next_slot = (32'(x) == THREADS - 1) ? '0 : x + 1'b1;
  endfunction  // the done-drops are over, the termination drops run
  logic pe_valid, pe_from_stage;
  logic [TW-1:0] pe_t;
  always_comb begin
    pe_from_stage = 1'b0;
    pe_valid = 1'b0;
    pe_t = pq[pq_head];
    if (pq_n != '0) pe_valid = 1'b1;
    else if (act == APop) begin
      pe_valid = 1'b1;
      pe_from_stage = 1'b1;
      pe_t = qt;
    end
  end

  // One entry: dropped, popped, or the level's stack is empty (the group ends).
  logic [SW-1:0] pe_size, pe_base;
  logic pe_empty, pe_done_drop, pe_term_drop, pe_drop, pe_phase2;
  logic [EW-1:0] pe_e;
  always_comb begin
    logic [SW-1:0] top;
    pe_size = size_r[pe_t];
    pe_base = base_r[pe_t];
    pe_empty = pe_size == pe_base;
    top = pe_empty ? '0 : pe_size - 1'b1;
    if (FAULT_POP_OFF && pe_size >= SW'(2)) top = pe_size - SW'(2);
    pe_e = EW'(pe_t) * EW'(STACK) + EW'(top);
    pe_phase2 = pe_from_stage ? 1'b0 : pop_phase2_r[pe_t];
    pe_done_drop = ~pe_phase2 & shadow_r[pe_t] & ((st_mask_m[pe_e] & ~done_r[pe_t]) == '0);
    pe_term_drop = 1'b1;
    for (int i = 0; i < P; i++)
      if (st_mask_m[pe_e][i] && !f_lt(tbest_r[pe_t][i], st_tn_m[pe_e][i])) pe_term_drop = 1'b0;
    pe_drop = ~pe_empty & (pe_done_drop | pe_term_drop);
  end
  logic pe_group_next;  // the level's stack is empty and another sign group follows
  assign pe_group_next = {1'b0, group_r[pe_t]} + 5'd1 < {1'b0, ngroups_r[pe_t]};

  // The outcome of a finished pop (pe_valid & ~pe_drop): next node, next group, or level end.
  logic [1:0] pe_dest;
  logic [NODE_W-1:0] pe_node;
  logic [P-1:0] pe_mask;
  always_comb begin
    pe_dest = DLoop;
    pe_node = st_node_m[pe_e];
    pe_mask = st_mask_m[pe_e];
    if (pe_empty) begin
      if (pe_group_next) begin
        pe_node = level_r[pe_t] ? root_r[pe_t] : top_root;
        pe_mask = groups_r[pe_t][3'(group_r[pe_t]+4'd1)];
      end else begin
        pe_dest = level_r[pe_t] ? DResume : DRgs;
        pe_node = '0;
        pe_mask = '0;
      end
    end
  end

  // The level's groups formed at the last clip face: the first group's start, or the level end.
  logic [1:0] gr_dest;
  assign gr_dest = ngrp != '0 ? DLoop : (level_r[qt] ? DResume : DRgs);

  // ---- outputs ------------------------------------------------------------------------------
  // One thread per cycle on each path to another unit (and on the loop), as the model's paths take
  // one push per cycle: the queue's head that decides while the last stage lets a thread go to the
  // same unit waits a cycle and decides again (nothing it read has changed).
  function automatic logic [1:0] dest_unit(input logic [1:0] d);
    dest_unit = d == DLoop ? 2'd0 : (d == DRgs ? 2'd2 : 2'd1);  // traversal, list, RGS
  endfunction
  logic pe_block, pe_go;
  assign pe_block = pe_valid && !pe_from_stage && !pe_drop && out_valid &&
                    dest_unit(out_dest) == dest_unit(pe_dest);
  assign pe_go = pe_valid && !pe_block;
  always_comb begin
    out_valid = 1'b0;
    out_thread = qt;
    out_dest = DLoop;
    out_node = '0;
    out_first = '0;
    out_end = '0;
    out_mask = '0;
    out_level = level_r[qt];
    case (act)
      AGroups: begin
        out_valid = 1'b1;
        out_dest = gr_dest;
        out_node = gr_dest != DLoop ? '0 : (level_r[qt] ? root_r[qt] : top_root);
        out_mask = grp[0];
      end
      ALeaf: begin
        out_valid = 1'b1;
        out_dest = DLeaf;
        out_first = c_q.first;
        out_end = c_q.first + {2'b0, c_q.count};
        out_mask = c_q.active;
      end
      APush, ANear: begin
        out_valid = 1'b1;
        out_node = near_child;
        out_mask = near_m;
      end
      AFar: begin
        out_valid = 1'b1;
        out_node = far_child;
        out_mask = far_m;
      end
      APop:
      if (pe_from_stage && !pe_drop) begin
        out_valid = 1'b1;
        out_dest = pe_dest;
        out_node = pe_node;
        out_mask = pe_mask;
      end
      default: ;
    endcase
    out2_valid = pe_go && !pe_from_stage && !pe_drop;
    out2_thread = pe_t;
    out2_dest = pe_dest;
    out2_node = pe_node;
    out2_mask = pe_mask;
    out2_level = level_r[pe_t];
  end

  // ---- the request each thread names next -----------------------------------------------------
  assign rq_clip = face_r[rq_thread] != 3'd7;
  assign rq_face = face_r[rq_thread];
  assign rq_node = node_r[rq_thread];
  assign rq_mask = rq_clip ? cmask_r[rq_thread] : mask_r[rq_thread];

  // Per load port: the origins inside the level's box (closed, value compares; NaN is outside):
  // exit faces only.
  logic [1:0] st_inside;
  always_comb begin
    for (int k = 0; k < 2; k++) begin
      st_inside[k] = 1'b1;
      for (int i = 0; i < P; i++) begin
        logic in_mask;
        in_mask = ld_bottom[k] ? ld_mask[k][i] : (ld_lane_valid[k][i] & ~ld_done[k][i]);
        for (int a = 0; a < 3; a++) begin
          logic [W-1:0] o, lo, hi;
          o = fld(ld_o[k][i], 2'(a));
          lo = ld_bottom[k] ? fld(ld_lo[k], 2'(a)) : fld(scene_lo, 2'(a));
          hi = ld_bottom[k] ? fld(ld_hi[k], 2'(a)) : fld(scene_hi, 2'(a));
          // !(o >= lo && o <= hi): o >= lo is !(o < lo) only when neither is NaN.
          if (in_mask && (f_nan(o) || f_lt(o, lo) || f_lt(hi, o))) st_inside[k] = 1'b0;
        end
      end
    end
  end

  // ---- state updates ---------------------------------------------------------------------------
  always_ff @(posedge clk) begin
    if (rst) begin
      cl_busy <= 1'b0;
      pq_n <= '0;
      pq_head <= '0;
      pq_tail <= '0;
      overflow <= 1'b0;
      for (int t = 0; t < THREADS; t++) begin
        face_r[t] <= 3'd7;
        size_r[t] <= '0;
        base_r[t] <= '0;
        level_r[t] <= 1'b0;
        ngroups_r[t] <= '0;
        group_r[t] <= '0;
      end
    end else begin
      // Level starts with their rays (TraversalStep::start_level; enter_object saves the top
      // level's groups), then hit updates: different threads.
      for (int k = 0; k < 2; k++)
        if (ld_valid[k]) begin
          if (ld_bottom[k]) begin
            oo[ld_thread[k]] <= ld_o[k];
            od[ld_thread[k]] <= ld_d[k];
            tgroups_r[ld_thread[k]] <= groups_r[ld_thread[k]];
            tngroups_r[ld_thread[k]] <= ngroups_r[ld_thread[k]];
            tgroup_r[ld_thread[k]] <= group_r[ld_thread[k]];
            tbase_r[ld_thread[k]] <= base_r[ld_thread[k]];
            blo_r[ld_thread[k]] <= ld_lo[k];
            bhi_r[ld_thread[k]] <= ld_hi[k];
            root_r[ld_thread[k]] <= ld_root[k];
            cmask_r[ld_thread[k]] <= ld_mask[k];
            ctf_r[ld_thread[k]] <= tbest_r[ld_thread[k]];
          end else begin
            wo[ld_thread[k]] <= ld_o[k];
            wd[ld_thread[k]] <= ld_d[k];
            tbest_r[ld_thread[k]] <= ld_tbest[k];
            done_r[ld_thread[k]] <= ld_done[k];
            cmask_r[ld_thread[k]] <= ld_lane_valid[k] & ~ld_done[k];
            shadow_r[ld_thread[k]] <= ld_shadow[k];
            ctf_r[ld_thread[k]] <= ld_tbest[k];
          end
          level_r[ld_thread[k]] <= ld_bottom[k];
          ctn_r[ld_thread[k]] <= '0;
          stride2_r[ld_thread[k]] <= EXIT_ONLY && st_inside[k];
          face_r[ld_thread[k]] <= EXIT_ONLY && st_inside[k] ? 3'd1 : 3'd0;
        end
      if (hu_valid) begin
        tbest_r[hu_thread] <= hu_tbest;
        done_r[hu_thread] <= hu_done;
      end

      // The clip chain issues its faces one per cycle.
      if (in_clip) begin
        cl_busy <= !in_last_face;
        cl_thread <= in_t;
        cl_face <= in_face + (stride2_r[in_t] ? 3'd2 : 3'd1);
        face_r[in_t] <= 3'd7;  // no clip request until the next level starts
      end

      // The last stage.
      case (act)
        AClipFace, AGroups: begin
          for (int i = 0; i < P; i++) begin
            ctn_r[qt][i] <= new_ctn[i];
            ctf_r[qt][i] <= new_ctf[i];
          end
          if (act == AGroups) begin
            for (int s = 0; s < 8; s++) groups_r[qt][s] <= grp[s];
            ngroups_r[qt] <= ngrp;
            group_r[qt] <= '0;
            base_r[qt] <= size_r[qt];
            if (ngrp != '0) begin
              node_r[qt] <= level_r[qt] ? root_r[qt] : top_root;
              mask_r[qt] <= grp[0];
              for (int i = 0; i < P; i++) begin
                tn_r[qt][i] <= new_ctn[i];
                tf_r[qt][i] <= new_ctf[i];
              end
            end else if (level_r[qt]) begin
              // An object none of whose rays hit its box: back to the top level's list.
              level_r[qt] <= 1'b0;
              groups_r[qt] <= tgroups_r[qt];
              ngroups_r[qt] <= tngroups_r[qt];
              group_r[qt] <= tgroup_r[qt];
              base_r[qt] <= tbase_r[qt];
            end
          end
        end
        APush: begin
          if (size_r[qt] == SW'(STACK)) overflow <= 1'b1;
          else begin
            st_node_m[EW'(qt)*EW'(STACK)+EW'(size_r[qt])] <= far_child;
            st_mask_m[EW'(qt)*EW'(STACK)+EW'(size_r[qt])] <= far_m;
            for (int i = 0; i < P; i++) begin
              st_tn_m[EW'(qt)*EW'(STACK)+EW'(size_r[qt])][i] <= far_tn[i];
              st_tf_m[EW'(qt)*EW'(STACK)+EW'(size_r[qt])][i] <= tf_r[qt][i];
            end
            size_r[qt] <= size_r[qt] + 1'b1;
          end
          for (int i = 0; i < P; i++) tf_r[qt][i] <= near_tf[i];
          node_r[qt] <= near_child;
          mask_r[qt] <= near_m;
        end
        ANear: begin
          if (skip_far) for (int i = 0; i < P; i++) tf_r[qt][i] <= near_tf[i];
          node_r[qt] <= near_child;
          mask_r[qt] <= near_m;
        end
        AFar: begin
          if (skip_near) for (int i = 0; i < P; i++) tn_r[qt][i] <= far_tn[i];
          node_r[qt] <= far_child;
          mask_r[qt] <= far_m;
        end
        default: ;
      endcase

      // The pop engine's entry of this cycle.
      if (pe_go) begin
        if (pe_drop) begin
          size_r[pe_t] <= pe_size - 1'b1;
          pop_phase2_r[pe_t] <= pe_phase2 | ~pe_done_drop;
        end else if (!pe_empty) begin
          size_r[pe_t] <= pe_size - 1'b1;
          node_r[pe_t] <= st_node_m[pe_e];
          mask_r[pe_t] <= st_mask_m[pe_e];
          for (int i = 0; i < P; i++) begin
            tn_r[pe_t][i] <= st_tn_m[pe_e][i];
            tf_r[pe_t][i] <= st_tf_m[pe_e][i];
          end
        end else if (pe_group_next) begin
          group_r[pe_t] <= group_r[pe_t] + 4'd1;
          node_r[pe_t] <= pe_node;
          mask_r[pe_t] <= pe_mask;
          for (int i = 0; i < P; i++) begin
            tn_r[pe_t][i] <= ctn_r[pe_t][i];
            tf_r[pe_t][i] <= ctf_r[pe_t][i];
          end
        end else if (level_r[pe_t]) begin
          level_r[pe_t] <= 1'b0;
          groups_r[pe_t] <= tgroups_r[pe_t];
          ngroups_r[pe_t] <= tngroups_r[pe_t];
          group_r[pe_t] <= tgroup_r[pe_t];
          base_r[pe_t] <= tbase_r[pe_t];
        end
        // The queue: a dropped entry keeps (or puts) its thread in it; a finished one leaves.
        if (pe_from_stage && pe_drop) begin
          pq[pq_tail] <= pe_t;
          pq_tail <= next_slot(pq_tail);
          pq_n <= pq_n + 1'b1;
        end else if (!pe_from_stage && !pe_drop) begin
          pq_head <= next_slot(pq_head);
          pq_n <= pq_n - 1'b1;
        end
      end
      // A pop asked for while the engine serves the queue joins it.
      if (act == APop && !pe_from_stage) begin
        pq[pq_tail] <= qt;
        pq_tail <= next_slot(pq_tail);
        pq_n <= (pe_go && !pe_drop) ? pq_n : pq_n + 1'b1;
        pop_phase2_r[qt] <= 1'b0;
      end
    end
  end

  assign dbg_tn = tn_r[dbg_thread][dbg_lane];
  assign dbg_tf = tf_r[dbg_thread][dbg_lane];
  assign dbg_ctn = ctn_r[dbg_thread][dbg_lane];
  assign dbg_ctf = ctf_r[dbg_thread][dbg_lane];
  assign dbg_size = size_r[dbg_thread];
  assign dbg_level = level_r[dbg_thread];
endmodule
