// Range soak client of fdml_localizer (issue 15, scripts/soak.sh; not part of make test).
// Publishes sensor_msgs/Range at RATE Hz for DURATION s, one message in every NEW_EVERY from a
// frame id never seen before (the rest from "range_sensor"), and every SAMPLE s prints the
// node's resident memory (VmRSS of PID) and its diagnostics. Exit status: 0 when memory grew by
// at most RSS_SLACK_MB after the first sample and the tf queue stayed within MAX_PENDING, 1
// otherwise, 2 on bad arguments or without diagnostics.
//   fdml_soak_client PID [DURATION=600] [RATE=1000] [SAMPLE=30] [NEW_EVERY=10] [RSS_SLACK_MB=8] [MAX_PENDING=10000]
#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/Range.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace
{
double rssMegabytes(int pid)
{
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
  {
    if (line.rfind("VmRSS:", 0) == 0)
    {
      return std::stod(line.substr(6)) / 1024.0;
    }
  }
  return -1.0;
}

class NodeDiagnostics
{
public:
  explicit NodeDiagnostics(ros::NodeHandle& nh)
    : sub_(nh.subscribe("/diagnostics", 10, &NodeDiagnostics::callback, this))
  {}

  long long get(const std::string& key)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = values_.find(key);
    return it == values_.end() ? -1 : std::stoll(it->second);
  }

private:
  void callback(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg)
  {
    for (const auto& status : msg->status)
    {
      std::map<std::string, std::string> values;
      for (const auto& kv : status.values)
      {
        values[kv.key] = kv.value;
      }
      if (values.count("readings received"))
      {
        std::lock_guard<std::mutex> lock(mutex_);
        values_ = values;
      }
    }
  }

  std::mutex mutex_;
  std::map<std::string, std::string> values_;
  ros::Subscriber sub_;
};

struct Sample
{
  double rss = 0.0;  ///< [MB]
  long long pending = 0;
  double t = 0.0;  ///< [s]
  long sent = 0;
};

double argument(const std::vector<std::string>& args, std::size_t i, double fallback)
{
  return i < args.size() ? std::stod(args[i]) : fallback;
}

struct Options
{
  int pid = 0;
  double duration = 600.0;  ///< [s]
  double rate = 1000.0;     ///< [Hz]
  double sample_period = 30.0;
  long new_every = 10;
  double rss_slack = 8.0;  ///< [MB]
  long long max_pending = 10000;
};

/// Publishes for the soak's duration, sampling the node; returns the samples.
std::vector<Sample> soak(const Options& o, ros::Publisher& pub, NodeDiagnostics& diagnostics)
{
  sensor_msgs::Range msg;
  msg.radiation_type = sensor_msgs::Range::ULTRASOUND;
  msg.field_of_view = 0.1f;
  msg.min_range = 0.05f;
  msg.max_range = 4.0f;
  msg.range = 1.5f;
  std::printf("t [s] | sent | rate [Hz] | VmRSS [MB] | received | dropped | waiting for tf | frames tracked | "
              "frames evicted\n");
  const ros::WallTime start = ros::WallTime::now();
  double next_sample = o.sample_period;
  long sent = 0;
  long new_frames = 0;
  std::vector<Sample> samples;
  while (ros::ok() && (ros::WallTime::now() - start).toSec() < o.duration)
  {
    const double delay = static_cast<double>(sent) / o.rate - (ros::WallTime::now() - start).toSec();
    if (delay > 0.0)
    {
      ros::WallDuration(delay).sleep();
    }
    msg.header.frame_id = sent % o.new_every == 0 ? "soak_" + std::to_string(new_frames++) : "range_sensor";
    msg.header.stamp = ros::Time::now();
    pub.publish(msg);
    ++sent;
    const double t = (ros::WallTime::now() - start).toSec();
    if (t >= next_sample)
    {
      next_sample += o.sample_period;
      Sample s{ rssMegabytes(o.pid), diagnostics.get("readings waiting for tf"), t, sent };
      samples.push_back(s);
      std::printf("%5.0f | %ld | %.0f | %.1f | %lld | %lld | %lld | %lld | %lld\n", t, sent, sent / t, s.rss,
                  diagnostics.get("readings received"), diagnostics.get("readings dropped"), s.pending,
                  diagnostics.get("sensor frames tracked"), diagnostics.get("sensor frames evicted"));
      std::fflush(stdout);
    }
  }
  std::printf("%ld new frame ids\n", new_frames);
  return samples;
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fdml_soak_client", ros::init_options::AnonymousName);
  std::vector<std::string> args;
  ros::removeROSArgs(argc, argv, args);
  if (args.size() < 2)
  {
    std::fprintf(stderr, "usage: fdml_soak_client PID [DURATION] [RATE] [SAMPLE] [NEW_EVERY] [RSS_SLACK_MB] "
                         "[MAX_PENDING]\n");
    return 2;
  }
  Options o;
  o.pid = std::stoi(args[1]);
  o.duration = argument(args, 2, o.duration);
  o.rate = argument(args, 3, o.rate);
  o.sample_period = argument(args, 4, o.sample_period);
  o.new_every = std::max(1L, static_cast<long>(argument(args, 5, 10.0)));
  o.rss_slack = argument(args, 6, o.rss_slack);
  o.max_pending = static_cast<long long>(argument(args, 7, 10000.0));

  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  NodeDiagnostics diagnostics(nh);
  ros::Publisher pub = nh.advertise<sensor_msgs::Range>("range", 1000);
  const ros::WallTime connect_deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  while (pub.getNumSubscribers() == 0 && ros::WallTime::now() < connect_deadline)
  {
    ros::WallDuration(0.05).sleep();
  }
  const std::vector<Sample> samples = soak(o, pub, diagnostics);
  if (samples.empty() || diagnostics.get("readings received") < 0)
  {
    std::fprintf(stderr, "no diagnostics from the node\n");
    return 2;
  }
  double peak = samples.front().rss;
  long long worst_pending = 0;
  for (const Sample& s : samples)
  {
    peak = std::max(peak, s.rss);
    worst_pending = std::max(worst_pending, s.pending);
  }
  const double growth = peak - samples.front().rss;
  std::printf("sent %ld messages in %.0f s: %.0f Hz; VmRSS %.1f MB at the first sample, peak growth %.1f MB; at "
              "most %lld readings waiting for tf\n",
              samples.back().sent, samples.back().t, samples.back().sent / samples.back().t, samples.front().rss,
              growth, worst_pending);
  return growth <= o.rss_slack && worst_pending <= o.max_pending ? 0 : 1;
}
