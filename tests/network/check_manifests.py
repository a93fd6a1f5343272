"""check_manifests.py SOURCE_DIRECTORY: consistency of the compose file and the Kubernetes manifests.

Parses deploy/compose.yaml and deploy/kubernetes/*.yaml (PyYAML) and checks what a cluster would
only reveal at run time: the coordinator connects to the names and ports the servers listen on,
the StatefulSet's pods get DNS names from a headless Service, the ConfigMap holds the shipped
case verbatim and mounts its meshes where the case expects them, labels and selectors agree,
and every container with a read-only root file system that runs a program writing to the
temporary directory (robin-coordinator and robin-run mesh each .geo body there; robin-run starts
robin-subdomain, whose libraries may write there) has a writable /tmp: a tmpfs in compose, an
emptyDir in Kubernetes.
Prints one line per file; exits 1 with the list of problems.
"""
import pathlib
import sys

import yaml

problems = []


def check(condition, message):
    if not condition:
        problems.append(message)
    return condition


def load_documents(path):
    with open(path) as handle:
        return [document for document in yaml.safe_load_all(handle) if document]


# Programs that write to the temporary directory (TMPDIR, else /tmp), and the image's default
# command (deploy/Dockerfile's CMD), which a container without `command` runs.
WRITES_TEMPORARY_FILES = {"robin-subdomain", "robin-run", "robin-coordinator"}
IMAGE_DEFAULT_PROGRAM = "robin-subdomain"


def program(command):
    return command[0] if command else IMAGE_DEFAULT_PROGRAM


def option_values(arguments, option):
    return [arguments[i + 1] for i, word in enumerate(arguments[:-1]) if word == option]


def listen_port(arguments):
    endpoints = option_values(arguments, "--listen")
    return endpoints[0].rsplit(":", 1)[1] if endpoints else None


def check_compose(source):
    path = source / "deploy/compose.yaml"
    services = load_documents(path)[0]["services"]
    check(set(services) == {"lower", "upper", "coordinator"}, f"{path}: services {sorted(services)}")
    coordinator = services["coordinator"]["command"]
    endpoints = option_values(coordinator, "--subdomain")
    expected = [f"tcp://{name}:{listen_port(services[name]['command'])}" for name in ("lower", "upper")]
    check(endpoints == expected, f"{path}: coordinator connects to {endpoints}, servers are {expected}")
    for name in ("lower", "upper"):
        port = listen_port(services[name]["command"])
        check(port in " ".join(services[name]["healthcheck"]["test"]),
              f"{path}: the health check of {name} does not probe port {port}")
        check(services["coordinator"]["depends_on"][name]["condition"] == "service_healthy",
              f"{path}: the coordinator does not wait for {name} to be healthy")
    for name, service in services.items():
        if service.get("read_only") and program(service.get("command")) in WRITES_TEMPORARY_FILES:
            tmpfs = service.get("tmpfs", [])
            tmpfs = [tmpfs] if isinstance(tmpfs, str) else tmpfs
            check("/tmp" in [entry.split(":", 1)[0] for entry in tmpfs],
                  f"{path}: service {name} runs {program(service.get('command'))} on a read-only "
                  f"root file system without a tmpfs at /tmp")
    case = coordinator[1]
    check(case.startswith("/opt/robin-contact/examples/") and
          (source / "examples" / case.split("/examples/", 1)[1]).is_file(),
          f"{path}: case {case} is not a shipped example")
    print(f"{path}: coordinator -> {', '.join(endpoints)}")


def by_kind(documents):
    objects = {}
    for document in documents:
        objects.setdefault(document["kind"], []).append(document)
    return objects


def check_servers(objects, path):
    """The StatefulSet and its headless Service; returns the endpoints of its pods."""
    statefulset, service = objects["StatefulSet"][0], objects["Service"][0]
    spec, labels = statefulset["spec"], statefulset["spec"]["template"]["metadata"]["labels"]
    check(service["spec"].get("clusterIP") == "None", f"{path}: the Service is not headless")
    check(spec["serviceName"] == service["metadata"]["name"],
          f"{path}: serviceName {spec['serviceName']} is not the Service")
    check(spec["replicas"] == 2, f"{path}: {spec['replicas']} replicas, one server per body needs 2")
    for selector in (spec["selector"]["matchLabels"], service["spec"]["selector"]):
        check(selector.items() <= labels.items(), f"{path}: selector {selector} misses the pods")
    container = spec["template"]["spec"]["containers"][0]
    port = listen_port(container["args"])
    check(str(container["ports"][0]["containerPort"]) == port,
          f"{path}: containerPort is not the --listen port {port}")
    check(str(service["spec"]["ports"][0]["port"]) == port, f"{path}: Service port is not {port}")
    name = statefulset["metadata"]["name"]
    return [f"tcp://{name}-{index}.{spec['serviceName']}:{port}" for index in range(2)], labels


def check_configmap(configmap, volume, source, path):
    """The ConfigMap holds the shipped case verbatim; returns the paths mounted from it."""
    data = configmap["data"]
    shipped = {"two_blocks.toml": "examples/two_blocks.toml",
               "block_lower.geo": "examples/meshes/block_lower.geo",
               "block_upper.geo": "examples/meshes/block_upper.geo"}
    for key, file in shipped.items():
        check(data.get(key) == (source / file).read_text(), f"{path}: key {key} differs from {file}")
    check(volume["configMap"]["name"] == configmap["metadata"]["name"],
          f"{path}: the Job mounts ConfigMap {volume['configMap']['name']}")
    for item in volume["configMap"]["items"]:
        check(item["key"] in data, f"{path}: the Job mounts a missing key {item['key']}")
    return {item["path"] for item in volume["configMap"]["items"]}


def check_temporary_directories(objects, path):
    """Every container (init containers too) with readOnlyRootFilesystem that runs a program
    of WRITES_TEMPORARY_FILES mounts a writable emptyDir at /tmp; returns how many do."""
    count = 0
    for kind in ("StatefulSet", "Job", "Deployment", "DaemonSet"):
        for workload in objects.get(kind, []):
            pod = workload["spec"]["template"]["spec"]
            volumes = {volume["name"]: volume for volume in pod.get("volumes", [])}
            for container in pod.get("initContainers", []) + pod["containers"]:
                read_only = container.get("securityContext", {}).get("readOnlyRootFilesystem")
                if not read_only or program(container.get("command")) not in WRITES_TEMPORARY_FILES:
                    continue
                mounts = [mount for mount in container.get("volumeMounts", [])
                          if mount["mountPath"] == "/tmp" and not mount.get("readOnly")]
                writable = mounts and "emptyDir" in volumes.get(mounts[0]["name"], {})
                count += bool(check(writable, f"{path}: container {container['name']} of {kind} "
                                              f"{workload['metadata']['name']} runs "
                                              f"{program(container.get('command'))} on a read-only "
                                              f"root file system without a writable emptyDir at /tmp"))
    return count


def check_kubernetes(source):
    directory = source / "deploy/kubernetes"
    kustomization = load_documents(directory / "kustomization.yaml")[0]
    documents = []
    for resource in kustomization["resources"]:
        documents += load_documents(directory / resource)
    objects = by_kind(documents)
    path = directory
    endpoints, server_labels = check_servers(objects, path)
    temporary_directories = check_temporary_directories(objects, path)
    job = objects["Job"][0]["spec"]["template"]
    container = job["spec"]["containers"][0]
    arguments = container["args"]
    check(option_values(arguments, "--subdomain") == endpoints,
          f"{path}: the Job connects to {option_values(arguments, '--subdomain')}, pods are {endpoints}")
    waited = job["spec"]["initContainers"][0]["command"][-1]
    for endpoint in endpoints:
        host = endpoint.split("//")[1].split(":")[0]
        check(host in waited, f"{path}: the init container does not wait for {host}")
    volumes = {volume["name"]: volume for volume in job["spec"]["volumes"]}
    mounts = {mount["name"]: mount["mountPath"] for mount in container["volumeMounts"]}
    mounted = check_configmap(objects["ConfigMap"][0], volumes["case"], source, path)
    case = arguments[0]
    check(case.startswith(mounts["case"] + "/") and case[len(mounts["case"]) + 1:] in mounted,
          f"{path}: case {case} is not mounted from the ConfigMap")
    case_text = objects["ConfigMap"][0]["data"][case.rsplit("/", 1)[1]]
    for line in case_text.splitlines():
        if line.startswith("mesh ="):
            mesh = line.split("=", 1)[1].strip().strip('"')
            check(mesh in mounted, f"{path}: mesh {mesh} of the case is not mounted")
    claim = volumes["results"]["persistentVolumeClaim"]["claimName"]
    check(claim in [c["metadata"]["name"] for c in objects["PersistentVolumeClaim"]],
          f"{path}: claim {claim} is not defined")
    policy = objects["NetworkPolicy"][0]["spec"]
    check(policy["podSelector"]["matchLabels"].items() <= server_labels.items(),
          f"{path}: the NetworkPolicy does not select the servers")
    allowed = policy["ingress"][0]["from"][0]["podSelector"]["matchLabels"]
    check(allowed.items() <= job["metadata"]["labels"].items(),
          f"{path}: the NetworkPolicy does not admit the coordinator's pods")
    print(f"{path}: {len(documents)} objects; Job -> {', '.join(endpoints)}; "
          f"{temporary_directories} read-only container(s) with an emptyDir at /tmp")


def main(source):
    source = pathlib.Path(source)
    for check_file in (check_compose, check_kubernetes):
        try:
            check_file(source)
        except (KeyError, IndexError, TypeError, yaml.YAMLError) as error:
            problems.append(f"{check_file.__name__}: unexpected structure: {error!r}")
    for problem in problems:
        print("PROBLEM:", problem)
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
