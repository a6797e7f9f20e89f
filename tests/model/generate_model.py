#!/usr/bin/env python3
"""generate_model.py CHANNELS: a robot-like model with CHANNELS channels (at least 3) on YAML stdout,
for the Event-Channel Diagram at scale (issue 23, item 6). Three kinds of flow, as in the paper's
robot: sensors on two CAN buses to perception on the LAN; planners on the LAN to actuators on
CAN; perception and planners to a logger on a second DDS domain and to visualization on LCM.
Most components both publish and subscribe, so the diagram draws them on both sides."""
import sys

channels = int(sys.argv[1]) if len(sys.argv) > 1 else 50
if channels < 3:
    sys.exit("generate_model.py: at least 3 channels")
sensing, acting = channels * 2 // 5, channels * 3 // 10
CAN_BUSES = ["body-can", "chassis-can"]

print("""gateway:
  name: wide-robot
  can_node_id: 1
  residence_bound: 500us
segments:
  - {name: body-can, type: can, interface: vcan0, bitrate: 1Mbit/s, max_utilization: 70%}
  - {name: chassis-can, type: can, interface: vcan1, bitrate: 1Mbit/s, max_utilization: 70%}
  - {name: lan, type: dds, domain: 0, latency_bound: 1ms, realtime: true, reliability: reliable}
  - {name: cloud, type: dds, domain: 1, latency_bound: 20ms}
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:7667?ttl=0", latency_bound: 5ms}
channels:""")

publishes, subscribes, segment_of = {}, {}, {}


def component(name, segment):
    segment_of[name] = segment
    publishes.setdefault(name, [])
    subscribes.setdefault(name, [])


for i in range(channels):
    name = f"ch{i:02d}"
    if i < sensing:  # a CAN sensor to perception on the LAN
        sensor, perception = f"sensor_{i // 3}", f"perception_{i % 4}"
        component(sensor, CAN_BUSES[(i // 3) % 2])
        component(perception, "lan")
        publishes[sensor].append(name)
        subscribes[perception].append(name)
        qos = f"class: {'hrt' if i % 4 == 0 else 'srt'}, period: {20 + 10 * (i % 5)}ms, reaction_time: {8 + 2 * (i % 3)}ms, omission_degree: 1"
    elif i < sensing + acting:  # a planner on the LAN to an actuator on CAN
        planner, actuator = f"planner_{i % 3}", f"actuator_{i % 5}"
        component(planner, "lan")
        component(actuator, CAN_BUSES[i % 2])
        publishes[planner].append(name)
        subscribes[actuator].append(name)
        qos = f"class: {'hrt' if i % 3 == 0 else 'srt'}, period: {20 + 10 * (i % 4)}ms, reaction_time: 10ms, omission_degree: 1"
    else:  # perception or planner to the logger and visualization
        source = f"perception_{i % 4}" if i % 2 else f"planner_{i % 3}"
        component(source, "lan")
        component("logger", "cloud")
        publishes[source].append(name)
        subscribes["logger"].append(name)
        if i % 3 == 0:
            component("visualization", "viz")
            subscribes["visualization"].append(name)
        qos = f"class: nrt, max_rate: {10 + i % 5 * 10}Hz, omission_degree: 5"
    print(f"  - {{name: {name}, subject: {0x200000000 + i:#018x}, {qos}, payload: 8B}}")

print("components:")
for name, segment in segment_of.items():
    print(f"  - name: {name}\n    segment: {segment}")
    if publishes[name]:
        print(f"    publishes: [{', '.join(publishes[name])}]")
    if subscribes[name]:
        print(f"    subscribes: [{', '.join(subscribes[name])}]")
