// tilth-fake-gige-camera ADDRESS SERIAL TRIGGER_CHECKS_HZ: Aravis's GigE Vision camera
// simulator, as arv-fake-gv-camera-0.8 runs it, looking for a software trigger
// TRIGGER_CHECKS_HZ times a second. The stock simulator looks 25 times a second, so its
// triggered frames leave up to 40 ms after their trigger, where a real camera exposes
// within microseconds. Runs until SIGTERM or SIGINT.
#include <signal.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include <arv.h>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: tilth-fake-gige-camera ADDRESS SERIAL TRIGGER_CHECKS_HZ\n");
    return 2;
  }
  const double checks_hz = std::atof(argv[3]);
  if (checks_hz <= 0.0) {
    std::fprintf(stderr, "tilth-fake-gige-camera: TRIGGER_CHECKS_HZ must be above 0, not '%s'\n",
                 argv[3]);
    return 2;
  }
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);  // before the simulator's threads

  ArvGvFakeCamera* simulator = arv_gv_fake_camera_new(argv[1], argv[2]);
  if (simulator == nullptr || !arv_gv_fake_camera_is_running(simulator)) {
    std::fprintf(stderr, "tilth-fake-gige-camera: cannot serve a camera on %s\n", argv[1]);
    return 1;
  }
  arv_fake_camera_set_trigger_frequency(arv_gv_fake_camera_get_fake_camera(simulator), checks_hz);
  int signal = 0;
  sigwait(&stop_signals, &signal);
  g_object_unref(simulator);
  return 0;
}
