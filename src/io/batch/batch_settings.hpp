// Who owns a batch's output folder: one set of settings (the command, outputs, parameters and
// database of a batch's header), their first difference in words, and the lock under which a run
// checks the folder's settings and writes its own header (docs/batch.md). Private to the library;
// settings_fingerprint is public (batch.hpp).
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace proxseg::detail {

// The settings of a batch's header: {"command", "database", "outputs", "parameters"} (null for
// one it has not). Two runs may share a folder when these are equal.
nlohmann::json batch_settings(const nlohmann::json& header);

// The first difference between the settings of two headers, "" when none: the path of the
// parameter and both values with the names given to them ("parameters/voxels/voxel_size (0.01
// earlier, 0.02 now)"), and how many more differ. A difference in paper_labels is named only when
// nothing else differs: every flag of stages 2-4 turns it on (apps/param_flags.cpp), so it
// differs along with the parameter the user changed.
std::string settings_difference(const nlohmann::json& a, const nlohmann::json& b,
                                const std::string& name_a, const std::string& name_b);

// The start of a batch as one step among the processes given the same folder: an exclusive
// flock on OUT/.proxseg-batch.lock, waited for, held while the object lives (the file is removed
// then: none is left in the folder). Under it a run checks the settings of the folder's logs and
// writes its own header, so that of two runs started together the second sees the first's.
class FolderGate {
 public:
  explicit FolderGate(const std::string& out_dir);
  ~FolderGate();
  FolderGate(const FolderGate&) = delete;
  FolderGate& operator=(const FolderGate&) = delete;

 private:
  std::string path_;
  int fd_ = -1;
};

// Refuses (InputError) a run into out_dir whose settings differ from those of any header in the
// folder's logs (OUT/summary*.jsonl), naming the log, the first difference and the ways out.
// The run's own log (own_log, a file name) counts on resume, or while another process writes it;
// otherwise this run starts it anew.
void check_folder_settings(const std::string& out_dir, const std::string& own_log,
                           const nlohmann::json& header, bool resume);

}  // namespace proxseg::detail
