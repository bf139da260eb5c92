// What the host uploads between the frames of a sequence (paper section 2: only the top-level
// index is rebuilt when objects move; section 5: "uploading changes to the scene between frames
// ... can be performed in parallel to rendering"). The host keeps the image it built; after a
// rebuild the words that differ from what the board holds are the upload. Whether that upload
// may run while the frame in flight renders depends on which words that frame reads: with two
// top-level copies (ImageParams::top_level_buffers = 2) the next frame's copy is written while
// the other one is read; docs/frames.md and decisions D46 give the rules.
#pragma once

#include <vector>

#include "host/image_builder.h"
#include "memif/image_format.h"

namespace saarcor::host {

// The words a frame reads while the registers name `built`'s current top-level copy: every data
// word of the scene banks (both levels' trees and lists, the instance records, the triangle
// matrices) except the other top-level copy's tree, lists and instance records; the shading
// bank's data; and the frame-buffer bank `frame_bank` the frame writes. With one top-level copy
// that is every data word.
std::vector<memif::BankRange> frame_reads(const BuiltImage& built, int frame_bank);

// Every data word of the shading and scene banks (what full_upload_bytes counts): the shading
// bank's data and, in each scene bank, the words of its kd-nodes, list entries and matrix rows.
std::vector<memif::BankRange> data_words(const BuiltImage& built);

// The words of banks 2-5 (shading and scene data; the frame-buffer banks are the hardware's) in
// which `after` differs from `before`, as runs of consecutive changed words, in bank and word
// order. Throws std::runtime_error when the images' bank sizes differ.
std::vector<memif::UploadRun> changed_words(const memif::MemoryImage& before,
                                            const memif::MemoryImage& after);

// True when a word of `runs` lies in one of `reads`.
bool overlaps(const std::vector<memif::UploadRun>& runs,
              const std::vector<memif::BankRange>& reads);

}  // namespace saarcor::host
