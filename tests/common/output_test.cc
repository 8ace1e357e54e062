// The output layer (docs/output.md): where each kind of path leads, what is kept, what is refused, and
// what is left after a failure or a signal. Processes and threads are synchronised through FIFOs and
// pipes, never by sleeping.
#include "cheval/common/output.h"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "cheval/common/error.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;

// A test run in the background of a non-interactive shell starts with SIGINT ignored; the output layer
// then leaves SIGINT alone, and the SIGINT test would wait for ever. Default dispositions first.
const bool kDefaultSignals = [] {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  return true;
}();

std::string ReadWhole(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteWhole(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

struct stat LinkStatus(const fs::path& path) {
  struct stat st {};
  EXPECT_EQ(::lstat(path.c_str(), &st), 0) << path;
  return st;
}

// Reads `fd` until EOF.
std::string Drain(int fd) {
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) != 0;) {
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    text.append(buffer, static_cast<size_t>(n));
  }
  return text;
}

// The message of the OutputError or UsageError `write` throws ("" when it throws nothing).
template <typename ErrorType, typename Function>
std::string MessageOf(Function&& write) {
  try {
    write();
  } catch (const ErrorType& e) {
    return e.what();
  }
  return "";
}

class OutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("cheval_output_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Names in the folder (and its subfolders) that are temporaries of the output layer.
  std::vector<std::string> Temporaries() const {
    std::vector<std::string> found;
    for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      if (name.find(".tmp-") != std::string::npos || name.find(".old-") != std::string::npos) found.push_back(name);
    }
    return found;
  }

  fs::path dir_;
};

// ---------------------------------------------------------------------------------------------
// Regular files.

// Several outputs of one command are written as one: all, or none replaced and no temporary left.
TEST_F(OutputTest, SeveralOutputsAreWrittenAllOrNothing) {
  const std::string a = Path("a.txt"), b = Path("b.txt");
  const std::vector<OutputFile> both{{a, "first\n"}, {b, "second\n"}};
  WriteOutputs(both);
  EXPECT_EQ(ReadWhole(a), "first\n");
  EXPECT_EQ(ReadWhole(b), "second\n");

  // The second file cannot be written (its folder does not exist): the first keeps its old text.
  const std::string missing = Path("no_such_folder/c.txt");
  const std::vector<OutputFile> failing{{a, "replaced\n"}, {missing, "x"}};
  try {
    WriteOutputs(failing);
    ADD_FAILURE() << "expected an OutputError";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing + ": error: cannot write: ", 0), 0u) << e.what();
  }
  EXPECT_EQ(ReadWhole(a), "first\n");
  size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) entries += entry.is_regular_file();
  EXPECT_EQ(entries, 2u);  // a.txt and b.txt: no temporary is left behind
}

// An output written a piece at a time: the pieces in order; what its function throws, and a write that
// fails part way, replace nothing and leave no temporary; the function stops at the failed write.
TEST_F(OutputTest, PiecewiseOutputsKeepTheAllOrNothingContract) {
  const std::string a = Path("a.txt"), b = Path("b.txt");
  const auto pieces = [](int count) {
    return [count](const TextSink& sink) {
      for (int i = 0; i < count; ++i) sink(std::to_string(i) + "\n");
    };
  };
  WriteOutputs(std::vector<OutputFile>{{a, pieces(3)}, {b, "whole\n"}});
  EXPECT_EQ(ReadWhole(a), "0\n1\n2\n");
  EXPECT_EQ(ReadWhole(b), "whole\n");

  // The function throws after two pieces: both files keep their old text.
  const std::vector<OutputFile> throwing{{b, "replaced\n"}, {a, [](const TextSink& sink) {
                                            sink("0\n");
                                            sink("1\n");
                                            throw ComputeError("row 2: not a number");
                                          }}};
  EXPECT_EQ(MessageOf<ComputeError>([&] { WriteOutputs(throwing); }), "row 2: not a number");
  EXPECT_EQ(ReadWhole(a), "0\n1\n2\n");
  EXPECT_EQ(ReadWhole(b), "whole\n");
  EXPECT_TRUE(Temporaries().empty());

  // A device that fails the first write: an OutputError, the function is not called again.
  int calls = 0;
  const std::vector<OutputFile> full{{b, "replaced\n"}, {"/dev/full", [&calls](const TextSink& sink) {
                                        for (int i = 0; i < 100; ++i, ++calls) sink("piece\n");
                                      }}};
  EXPECT_EQ(MessageOf<OutputError>([&] { WriteOutputs(full); }),
            std::string("/dev/full: error: cannot write: ") + std::strerror(ENOSPC));
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(ReadWhole(b), "whole\n");
  EXPECT_TRUE(Temporaries().empty());
}

TEST_F(OutputTest, NewFileGetsTheUmaskMode) {
  const mode_t mask = ::umask(0);
  ::umask(mask);
  WriteOutput(Path("new.txt"), "text\n");
  EXPECT_EQ(ReadWhole(Path("new.txt")), "text\n");
  EXPECT_EQ(LinkStatus(Path("new.txt")).st_mode & 07777, 0666 & ~mask);
  EXPECT_TRUE(Temporaries().empty());
}

// Issue 13: a 0600 output became 0644 (the temporary's mode) when it was replaced.
TEST_F(OutputTest, ReplacedFileKeepsItsMode) {
  WriteWhole(Path("secret.txt"), "old\n");
  fs::permissions(Path("secret.txt"), fs::perms::owner_read | fs::perms::owner_write);
  WriteOutput(Path("secret.txt"), "new\n");
  EXPECT_EQ(ReadWhole(Path("secret.txt")), "new\n");
  EXPECT_EQ(LinkStatus(Path("secret.txt")).st_mode & 07777, 0600u);
  ::chmod(Path("secret.txt").c_str(), 0640);
  WriteOutput(Path("secret.txt"), "newer\n");
  EXPECT_EQ(LinkStatus(Path("secret.txt")).st_mode & 07777, 0640u);
}

TEST_F(OutputTest, ReplacedFileKeepsItsOwnerWherePermitted) {
  if (::geteuid() != 0) GTEST_SKIP() << "only root may give a file to another owner";
  WriteWhole(Path("theirs.txt"), "old\n");
  ASSERT_EQ(::chown(Path("theirs.txt").c_str(), 4321, 4322), 0);
  WriteOutput(Path("theirs.txt"), "new\n");
  EXPECT_EQ(ReadWhole(Path("theirs.txt")), "new\n");
  EXPECT_EQ(LinkStatus(Path("theirs.txt")).st_uid, 4321u);
  EXPECT_EQ(LinkStatus(Path("theirs.txt")).st_gid, 4322u);
}

// ---------------------------------------------------------------------------------------------
// Symlinks: the target is replaced, the link is kept.

TEST_F(OutputTest, SymlinkTargetIsReplacedAndTheLinkKept) {
  WriteWhole(Path("real.txt"), "old\n");
  fs::create_symlink("real.txt", Path("link.txt"));  // relative: resolved from the link's folder
  fs::create_symlink("link.txt", Path("chain.txt"));
  WriteOutput(Path("chain.txt"), "new\n");
  EXPECT_TRUE(S_ISLNK(LinkStatus(Path("chain.txt")).st_mode));
  EXPECT_TRUE(S_ISLNK(LinkStatus(Path("link.txt")).st_mode));
  EXPECT_EQ(ReadWhole(Path("real.txt")), "new\n");
  EXPECT_TRUE(Temporaries().empty());
}

TEST_F(OutputTest, DanglingSymlinkCreatesItsTarget) {
  fs::create_directories(Path("sub"));
  fs::create_symlink("sub/made.txt", Path("dangling.txt"));
  WriteOutput(Path("dangling.txt"), "made\n");
  EXPECT_TRUE(S_ISLNK(LinkStatus(Path("dangling.txt")).st_mode));
  EXPECT_EQ(ReadWhole(Path("sub/made.txt")), "made\n");
  EXPECT_TRUE(Temporaries().empty());
}

TEST_F(OutputTest, SymlinkLoopIsAnOutputError) {
  fs::create_symlink("b", Path("a"));
  fs::create_symlink("a", Path("b"));
  EXPECT_EQ(MessageOf<OutputError>([&] { WriteOutput(Path("a"), "x"); }),
            Path("a") + ": error: cannot write: " + std::strerror(ELOOP));
}

// ---------------------------------------------------------------------------------------------
// Special files are written in place.

// Issue 13: `-o FIFO` replaced the FIFO by a regular file. The reader is open before the write, so
// the text (smaller than a pipe's buffer) is waiting in the FIFO when WriteOutput returns.
TEST_F(OutputTest, FifoStaysAFifoAndGetsTheText) {
  ASSERT_EQ(::mkfifo(Path("fifo").c_str(), 0600), 0);
  const int reader = ::open(Path("fifo").c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  WriteOutput(Path("fifo"), "through the fifo\n");
  EXPECT_TRUE(S_ISFIFO(LinkStatus(Path("fifo")).st_mode));
  EXPECT_EQ(Drain(reader), "through the fifo\n");
  ::close(reader);
}

// A text larger than the pipe's buffer: the writer blocks until a reader thread takes it all.
TEST_F(OutputTest, FifoTakesALargeTextFromAReaderThread) {
  ASSERT_EQ(::mkfifo(Path("fifo").c_str(), 0600), 0);
  const int reader = ::open(Path("fifo").c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  const int keep_open = ::open(Path("fifo").c_str(), O_WRONLY);  // until WriteOutput is done, reads block
  ASSERT_GE(keep_open, 0);
  ASSERT_EQ(::fcntl(reader, F_SETFL, 0), 0);
  std::string text(1 << 20, 'x');
  for (size_t i = 0; i < text.size(); i += 4096) text[i] = static_cast<char>('a' + (i / 4096) % 26);
  std::string received;
  std::thread thread([&] { received = Drain(reader); });
  WriteOutput(Path("fifo"), text);
  ::close(keep_open);  // EOF for the reader
  thread.join();
  ::close(reader);
  EXPECT_TRUE(S_ISFIFO(LinkStatus(Path("fifo")).st_mode));
  EXPECT_EQ(received.size(), text.size());
  EXPECT_TRUE(received == text);
}

// Issue 13: `-o /dev/null` replaced /dev/null (as root) by a regular file.
TEST_F(OutputTest, DevNullStaysACharacterDevice) {
  WriteOutput("/dev/null", "nothing\n");
  EXPECT_TRUE(S_ISCHR(LinkStatus("/dev/null").st_mode));
}

TEST_F(OutputTest, FullDeviceIsAnOutputErrorAndReplacesNothing) {
  EXPECT_EQ(MessageOf<OutputError>([] { WriteOutput("/dev/full", "x"); }),
            std::string("/dev/full: error: cannot write: ") + std::strerror(ENOSPC));
  EXPECT_TRUE(S_ISCHR(LinkStatus("/dev/full").st_mode));
  // With a regular file beside it: that file is not written either, and no temporary is left.
  WriteWhole(Path("kept.txt"), "old\n");
  const std::vector<OutputFile> both{{Path("kept.txt"), "new\n"}, {"/dev/full", "x"}};
  EXPECT_FALSE(MessageOf<OutputError>([&] { WriteOutputs(both); }).empty());
  EXPECT_EQ(ReadWhole(Path("kept.txt")), "old\n");
  EXPECT_TRUE(Temporaries().empty());
}

// Standard output is pointed at `fd` for the life of the object (and flushed around it).
class RedirectStdout {
 public:
  explicit RedirectStdout(int fd) : saved_(::dup(STDOUT_FILENO)) {
    std::fflush(stdout);
    ::dup2(fd, STDOUT_FILENO);
  }
  ~RedirectStdout() {
    std::fflush(stdout);
    ::dup2(saved_, STDOUT_FILENO);
    ::close(saved_);
  }

 private:
  int saved_;
};

// Issue 13: `--json -` created a file named `-`; `--json /dev/stdout` replaced the /dev/stdout link.
TEST_F(OutputTest, DashAndDevStdoutWriteToStandardOutput) {
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  {
    RedirectStdout redirect(pipe_fds[1]);
    ::close(pipe_fds[1]);
    std::printf("printed first\n");  // C stdio's buffer comes before the output
    WriteOutput("-", "dash\n");
    WriteOutput("/dev/stdout", "dev stdout\n");
    WriteOutput("/dev/fd/1", "dev fd 1\n");
    WriteOutput("/proc/self/fd/1", "proc self fd 1\n");
  }
  EXPECT_EQ(Drain(pipe_fds[0]), "printed first\ndash\ndev stdout\ndev fd 1\nproc self fd 1\n");
  ::close(pipe_fds[0]);
  EXPECT_TRUE(S_ISLNK(LinkStatus("/dev/stdout").st_mode));
  EXPECT_FALSE(fs::exists("-"));
}

// Issue 13: results written to a full standard output were lost with exit 0.
TEST_F(OutputTest, FullStandardOutputIsAnOutputError) {
  const int full = ::open("/dev/full", O_WRONLY);
  ASSERT_GE(full, 0);
  std::string message;
  {
    RedirectStdout redirect(full);
    message = MessageOf<OutputError>([] { WriteOutput("-", "lost\n"); });
  }
  ::close(full);
  EXPECT_EQ(message, std::string("<stdout>: error: cannot write: ") + std::strerror(ENOSPC));
}

// With SIGPIPE ignored (as in Python), a closed pipe is an OutputError too.
TEST_F(OutputTest, ClosedPipeIsAnOutputErrorWhenSigpipeIsIgnored) {
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  ::close(pipe_fds[0]);
  struct sigaction ignore {}, old {};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGPIPE, &ignore, &old);
  std::string message;
  {
    RedirectStdout redirect(pipe_fds[1]);
    message = MessageOf<OutputError>([] { WriteOutput("-", "nobody reads\n"); });
  }
  ::sigaction(SIGPIPE, &old, nullptr);
  ::close(pipe_fds[1]);
  EXPECT_EQ(message, std::string("<stdout>: error: cannot write: ") + std::strerror(EPIPE));
}

TEST_F(OutputTest, FolderIsAnOutputError) {
  fs::create_directories(Path("folder"));
  EXPECT_EQ(MessageOf<OutputError>([&] { WriteOutput(Path("folder"), "x"); }),
            Path("folder") + ": error: cannot write: " + std::strerror(EISDIR));
}

// ---------------------------------------------------------------------------------------------
// Same-file checks.

std::string CheckMessage(const std::vector<std::string>& inputs, const std::vector<OutputPath>& outputs) {
  return MessageOf<UsageError>([&] { CheckOutputs(inputs, outputs); });
}

TEST_F(OutputTest, OutputThatIsAnInputIsRefused) {
  const std::string input = Path("ref.txt");
  WriteWhole(input, "ref\n");
  EXPECT_EQ(CheckMessage({input}, {{"--json", input}}), "--json " + input + " names the same file as the input " + input);
  // Without a label, by another spelling of the same path.
  const std::string dotted = (dir_ / "." / "ref.txt").string();
  EXPECT_EQ(CheckMessage({input}, {{"", dotted}}), "output " + dotted + " names the same file as the input " + input);
  fs::create_directories(Path("sub"));
  EXPECT_NE(CheckMessage({input}, {{"-o", Path("sub/../ref.txt")}}), "");
  // A hard link and a symlink to it.
  fs::create_hard_link(input, Path("hard.txt"));
  fs::create_symlink("ref.txt", Path("soft.txt"));
  EXPECT_NE(CheckMessage({input}, {{"-o", Path("hard.txt")}}), "");
  EXPECT_NE(CheckMessage({input}, {{"-o", Path("soft.txt")}}), "");
  EXPECT_NE(CheckMessage({Path("soft.txt")}, {{"-o", input}}), "");
}

TEST_F(OutputTest, RelativeAndAbsoluteSpellingsAreOneFile) {
  WriteWhole(Path("x.txt"), "x\n");
  const fs::path before = fs::current_path();
  fs::current_path(dir_);
  const std::string relative = CheckMessage({"x.txt"}, {{"-o", "./x.txt"}});
  const std::string fresh = CheckMessage({}, {{"-o", "new.txt"}, {"--json", Path("new.txt")}});
  fs::current_path(before);
  EXPECT_EQ(relative, "-o ./x.txt names the same file as the input x.txt");
  EXPECT_EQ(fresh, "-o new.txt and --json " + Path("new.txt") + " name the same file");
}

// Outputs that do not exist yet are compared by canonical folder and name.
TEST_F(OutputTest, NewOutputsInASymlinkedFolderAreOneFile) {
  fs::create_directories(Path("real"));
  fs::create_directory_symlink("real", Path("alias"));
  EXPECT_EQ(CheckMessage({}, {{"-o", Path("alias/new.txt")}, {"--json", Path("real/new.txt")}}),
            "-o " + Path("alias/new.txt") + " and --json " + Path("real/new.txt") + " name the same file");
  EXPECT_EQ(CheckMessage({}, {{"-o", Path("alias/new.txt")}, {"--json", Path("real/other.txt")}}), "");
  // A dangling symlink leads to the name it would create.
  fs::create_symlink("real/new.txt", Path("dangling"));
  EXPECT_NE(CheckMessage({}, {{"-o", Path("dangling")}, {"--json", Path("alias/new.txt")}}), "");
}

TEST_F(OutputTest, TwoOutputsOnOnePathAreRefused) {
  const std::string out = Path("out.json");
  EXPECT_EQ(CheckMessage({}, {{"--json", out}, {"-o", out}}), "--json " + out + " and -o " + out + " name the same file");
  WriteWhole(out, "old\n");
  EXPECT_NE(CheckMessage({}, {{"--json", out}, {"-o", out}}), "");
  // WriteOutputs refuses it too (before, one of the two was silently lost).
  const std::vector<OutputFile> twice{{out, "first\n"}, {out, "second\n"}};
  EXPECT_EQ(MessageOf<UsageError>([&] { WriteOutputs(twice); }), "output " + out + " and output " + out + " name the same file");
  EXPECT_EQ(ReadWhole(out), "old\n");
}

TEST_F(OutputTest, StandardOutputTwiceIsRefusedAsInputItIsNot) {
  EXPECT_EQ(CheckMessage({}, {{"--json", "-"}, {"-o", "-"}}), "--json - and -o - both write to standard output");
  EXPECT_EQ(CheckMessage({"-"}, {{"-o", "-"}}), "");
  // `-` and /dev/stdout while standard output is a pipe: the same pipe.
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  std::string message;
  {
    RedirectStdout redirect(pipe_fds[1]);
    message = CheckMessage({}, {{"--json", "/dev/stdout"}, {"-o", "-"}});
  }
  ::close(pipe_fds[0]);
  ::close(pipe_fds[1]);
  EXPECT_EQ(message, "--json /dev/stdout and -o - both write to standard output");
}

TEST_F(OutputTest, CharacterDevicesMayRepeat) {
  EXPECT_EQ(CheckMessage({"/dev/null"}, {{"--json", "/dev/null"}, {"-o", "/dev/null"}}), "");
}

TEST_F(OutputTest, DistinctAndMissingOutputsPass) {
  WriteWhole(Path("in.txt"), "in\n");
  EXPECT_EQ(CheckMessage({Path("in.txt"), "", "-"}, {{"-o", Path("a.txt")}, {"--json", ""}, {"--csv", Path("b.txt")}}),
            "");
}

TEST_F(OutputTest, FolderKindsAreChecked) {
  fs::create_directories(Path("full"));
  WriteWhole(Path("full/in.txt"), "in\n");
  fs::create_directories(Path("empty"));
  EXPECT_EQ(CheckMessage({}, {{"-o", Path("full")}}), "-o " + Path("full") + " is a folder");
  EXPECT_EQ(CheckMessage({}, {{"-o", Path("full"), OutputKind::kNewFolder}}),
            "-o " + Path("full") + " exists and is not an empty folder");
  EXPECT_EQ(CheckMessage({}, {{"-o", Path("empty"), OutputKind::kNewFolder}}), "");
  EXPECT_EQ(CheckMessage({}, {{"-o", Path("new"), OutputKind::kNewFolder}}), "");
  EXPECT_EQ(CheckMessage({Path("full/in.txt")}, {{"-o", Path("full"), OutputKind::kReplacedFolder}}),
            "-o " + Path("full") + " holds the input " + Path("full/in.txt") +
                ": replacing the folder would remove it");
  EXPECT_EQ(CheckMessage({Path("full/in.txt")}, {{"-o", Path("full/in.txt"), OutputKind::kReplacedFolder}}),
            "-o " + Path("full/in.txt") + " exists and is not a folder");
  EXPECT_EQ(CheckMessage({}, {{"-o", Path("full"), OutputKind::kReplacedFolder}}), "");
}

// ---------------------------------------------------------------------------------------------
// Staged folders.

std::vector<std::string> Names(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST_F(OutputTest, FolderIsPublishedWhole) {
  const std::vector<OutputFile> files{{"a.csv", "a\n"}, {"b.csv", "b\n"}};
  WriteFolder(Path("out"), files);
  EXPECT_EQ(Names(Path("out")), (std::vector<std::string>{"a.csv", "b.csv"}));
  EXPECT_EQ(ReadWhole(Path("out/b.csv")), "b\n");
  EXPECT_TRUE(Temporaries().empty());
  // An empty folder is replaced by the one rename.
  fs::create_directories(Path("empty"));
  WriteFolder(Path("empty"), files);
  EXPECT_EQ(Names(Path("empty")), (std::vector<std::string>{"a.csv", "b.csv"}));
}

TEST_F(OutputTest, FailedFolderLeavesNoStagingAndTheOldFolder) {
  fs::create_directories(Path("out"));
  WriteWhole(Path("out/old.csv"), "old\n");
  {
    StagedFolder folder(Path("out"));
    folder.Write("a.csv", "a\n");
    EXPECT_EQ(MessageOf<OutputError>([&] { folder.Write("a.csv", "again\n"); }),
              Path("out") + "/a.csv: error: cannot write: " + std::strerror(EEXIST));
    ASSERT_EQ(Temporaries().size(), 1u);  // the staging folder, beside the target
    EXPECT_EQ(Names(dir_ / Temporaries()[0]), std::vector<std::string>{"a.csv"});
  }  // not published: a failure
  EXPECT_EQ(Names(Path("out")), std::vector<std::string>{"old.csv"});
  EXPECT_TRUE(Temporaries().empty());
  EXPECT_FALSE(MessageOf<UsageError>([&] { StagedFolder(Path("out")).Write("sub/a.csv", ""); }).empty());
  EXPECT_TRUE(Temporaries().empty());
}

TEST_F(OutputTest, ExistingFolderIsRefusedOrReplacedWhole) {
  fs::create_directories(Path("out"));
  WriteWhole(Path("out/old.csv"), "old\n");
  WriteWhole(Path("out/other.csv"), "other\n");
  ::chmod(Path("out").c_str(), 0700);
  const std::vector<OutputFile> files{{"a.csv", "a\n"}};
  EXPECT_EQ(MessageOf<OutputError>([&] { WriteFolder(Path("out"), files); }),
            Path("out") + ": error: cannot write: the folder exists and is not empty");
  EXPECT_EQ(Names(Path("out")), (std::vector<std::string>{"old.csv", "other.csv"}));
  EXPECT_TRUE(Temporaries().empty());
  WriteFolder(Path("out"), files, FolderExisting::kReplace);
  EXPECT_EQ(Names(Path("out")), std::vector<std::string>{"a.csv"});  // no file of the old run is left
  EXPECT_EQ(LinkStatus(Path("out")).st_mode & 07777, 0700u);
  EXPECT_TRUE(Temporaries().empty());
}

TEST_F(OutputTest, FolderThroughASymlinkReplacesItsTarget) {
  fs::create_directories(Path("real"));
  WriteWhole(Path("real/old.csv"), "old\n");
  fs::create_directory_symlink("real", Path("alias"));
  const std::vector<OutputFile> files{{"a.csv", "a\n"}};
  WriteFolder(Path("alias"), files, FolderExisting::kReplace);
  EXPECT_TRUE(S_ISLNK(LinkStatus(Path("alias")).st_mode));
  EXPECT_EQ(Names(Path("real")), std::vector<std::string>{"a.csv"});
  EXPECT_TRUE(Temporaries().empty());
}

TEST_F(OutputTest, FolderOntoAFileIsAnOutputError) {
  WriteWhole(Path("file"), "x\n");
  EXPECT_EQ(MessageOf<OutputError>([&] { StagedFolder folder(Path("file")); }),
            Path("file") + ": error: cannot write: " + std::strerror(ENOTDIR));
}

// ---------------------------------------------------------------------------------------------
// A signal during the write phase.

// A child stages `out.txt` (and, with `folder`, a staging folder with one file), then blocks writing
// 1 MiB into a FIFO nobody reads. Once the FIFO has data the child is inside the write phase; it gets
// `signal` and must die of it leaving no temporary. Before, `.out.txt.tmp-*` stayed behind.
void ExpectSignalLeavesNoTemporary(const fs::path& dir, int signal, bool folder) {
  const std::string fifo = (dir / "fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // the child's open does not block
  ASSERT_GE(reader, 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      const std::string big(1 << 20, 'x');
      std::optional<StagedFolder> staged;
      if (folder) {
        staged.emplace((dir / "out_folder").string());
        staged->Write("a.csv", "a\n");
      }
      const std::vector<OutputFile> files{{(dir / "out.txt").string(), "out\n"}, {fifo, big}};
      WriteOutputs(files);
    } catch (...) {
      ::_exit(2);
    }
    ::_exit(1);  // not reached: nobody reads the FIFO to its end
  }
  pollfd ready{reader, POLLIN, 0};
  const int polled = ::poll(&ready, 1, 60'000);  // a safety net only: the child writes at once
  EXPECT_EQ(polled, 1);
  ::kill(child, signal);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ::close(reader);
  EXPECT_TRUE(WIFSIGNALED(status)) << "exit status " << status;
  if (WIFSIGNALED(status)) {
    EXPECT_EQ(WTERMSIG(status), signal);
  }
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir)) left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"fifo"});
}

TEST_F(OutputTest, SigtermDuringTheWriteLeavesNoTemporary) { ExpectSignalLeavesNoTemporary(dir_, SIGTERM, false); }

TEST_F(OutputTest, SigintDuringTheWriteLeavesNoTemporary) { ExpectSignalLeavesNoTemporary(dir_, SIGINT, false); }

TEST_F(OutputTest, SigtermLeavesNoStagingFolder) { ExpectSignalLeavesNoTemporary(dir_, SIGTERM, true); }

}  // namespace
}  // namespace cheval
