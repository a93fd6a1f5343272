"""check_manifests.py SOURCE_DIRECTORY [--rendered NAME FILE ...]: consistency of the compose
files and the Kubernetes manifests.

Parses deploy/compose.yaml (the two-body run) with each override deploy/compose.*.yaml merged
over it (deploy/compose.four-bodies.yaml: four bodies), and the kustomizations
deploy/kubernetes (the two-body run, base/) and deploy/kubernetes/four-bodies (an overlay:
replicas and a strategic merge patch of the Job, applied here as kustomize does for these
files), all with PyYAML, and checks what a cluster would only reveal at run time: there is one
server per body of the case (the number of [[body]] tables of the shipped case the coordinator
solves = the servers = its --subdomain endpoints), the coordinator connects to the names and
ports the servers listen on and waits for every one, the StatefulSet's pods get DNS names from
a headless Service, the ConfigMap holds the shipped case verbatim and mounts its meshes where
the case expects them, labels and selectors agree, and every container with a read-only root
file system that runs a program writing to the temporary directory (robin-coordinator and
robin-run mesh each .geo body there; robin-run starts robin-subdomain, whose libraries may
write there) has a writable /tmp: a tmpfs in compose, an emptyDir in Kubernetes.

--rendered NAME FILE checks FILE, the output of `kubectl kustomize` for the kustomization NAME
(a directory under deploy/kubernetes, "." for deploy/kubernetes itself), the same way, and that
it has the objects and replicas this script's own reading of NAME has.
Prints one line per compose model and kustomization; exits 1 with the list of problems.
"""
import copy
import pathlib
import re
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
BODY_TABLE = re.compile(r"^\s*\[\[\s*body\s*\]\]", re.MULTILINE)


def program(command):
    return command[0] if command else IMAGE_DEFAULT_PROGRAM


def option_values(arguments, option):
    return [arguments[i + 1] for i, word in enumerate(arguments[:-1]) if word == option]


def listen_port(arguments):
    endpoints = option_values(arguments, "--listen")
    return endpoints[0].rsplit(":", 1)[1] if endpoints else None


def body_count(case_text):
    """The number of [[body]] tables of a case file: the servers it needs (one per body)."""
    return len(BODY_TABLE.findall(case_text))


# --- Compose ----------------------------------------------------------------------------------

def merge_compose(base, override):
    """Compose's merge of an override file into a model (the cases these files use): services
    merge key by key; `command` is replaced, mappings (depends_on, ...) merge."""
    merged = copy.deepcopy(base)
    for name, service in override.get("services", {}).items():
        target = merged["services"].setdefault(name, {})
        for key, value in service.items():
            if isinstance(value, dict) and isinstance(target.get(key), dict):
                target[key] = {**target[key], **value}
            else:
                target[key] = copy.deepcopy(value)
    return merged


def resolve_extends(model, directory):
    """Replaces each service's `extends: {file, service}` by the service it extends, with the
    service's own keys over it (compose's rule for these keys)."""
    for name, service in model["services"].items():
        extends = service.pop("extends", None)
        if extends is None:
            continue
        source = model
        if "file" in extends:
            source = load_documents(directory / extends["file"])[0]
        check(extends["service"] in source["services"],
              f"service {name} extends an unknown service {extends['service']}")
        base = copy.deepcopy(source["services"].get(extends["service"], {}))
        base.pop("depends_on", None)  # never inherited
        base.update(service)
        model["services"][name] = base
    return model


def check_compose_model(model, path, source):
    services = model["services"]
    check("coordinator" in services, f"{path}: no coordinator service")
    coordinator = services["coordinator"]["command"]
    servers = [name for name, service in services.items()
               if name != "coordinator" and program(service.get("command")) == "robin-subdomain"]
    endpoints = option_values(coordinator, "--subdomain")
    expected = [f"tcp://{name}:{listen_port(services[name]['command'])}" for name in servers]
    check(sorted(endpoints) == sorted(expected) and len(set(endpoints)) == len(endpoints),
          f"{path}: coordinator connects to {endpoints}, servers are {expected}")
    for name in servers:
        port = listen_port(services[name]["command"])
        check(port in " ".join(services[name]["healthcheck"]["test"]),
              f"{path}: the health check of {name} does not probe port {port}")
        check((services["coordinator"].get("depends_on", {}).get(name) or {}).get("condition")
              == "service_healthy", f"{path}: the coordinator does not wait for {name} to be "
                                    "healthy")
    for name, service in services.items():
        if service.get("read_only") and program(service.get("command")) in WRITES_TEMPORARY_FILES:
            tmpfs = service.get("tmpfs", [])
            tmpfs = [tmpfs] if isinstance(tmpfs, str) else tmpfs
            check("/tmp" in [entry.split(":", 1)[0] for entry in tmpfs],
                  f"{path}: service {name} runs {program(service.get('command'))} on a read-only "
                  f"root file system without a tmpfs at /tmp")
    case = coordinator[1]
    shipped = source / "examples" / case.split("/examples/", 1)[-1]
    if check(case.startswith("/opt/robin-contact/examples/") and shipped.is_file(),
             f"{path}: case {case} is not a shipped example"):
        bodies = body_count(shipped.read_text())
        check(bodies == len(servers) == len(endpoints),
              f"{path}: the case {case} has {bodies} bodies, the model {len(servers)} servers "
              f"and the coordinator {len(endpoints)} endpoints: one server per body")
    print(f"{path}: {len(servers)} servers; coordinator -> {', '.join(endpoints)}")
    return len(servers)


def check_compose(source):
    directory = source / "deploy"
    base = load_documents(directory / "compose.yaml")[0]
    servers = check_compose_model(resolve_extends(copy.deepcopy(base), directory),
                                  directory / "compose.yaml", source)
    check(servers == 2, f"{directory}/compose.yaml: {servers} servers; the default run is the "
                        "two-body example")
    for override in sorted(directory.glob("compose.*.yaml")):
        model = merge_compose(base, load_documents(override)[0])
        check_compose_model(resolve_extends(model, directory),
                            f"{directory}/compose.yaml + {override.name}", source)


# --- Kubernetes --------------------------------------------------------------------------------

def by_kind(documents):
    objects = {}
    for document in documents:
        objects.setdefault(document["kind"], []).append(document)
    return objects


def strategic_merge(target, patch):
    """Kubernetes' strategic merge for these manifests: mappings merge; lists of mappings with a
    `name` (containers, initContainers, volumes, env, volumeMounts) merge item by item by name;
    other lists (args, command, items) are replaced."""
    if isinstance(target, dict) and isinstance(patch, dict):
        for key, value in patch.items():
            target[key] = strategic_merge(target[key], value) if key in target else value
        return target
    if (isinstance(target, list) and isinstance(patch, list) and patch
            and all(isinstance(item, dict) and "name" in item for item in target + patch)):
        merged = {item["name"]: item for item in target}
        for item in patch:
            merged[item["name"]] = (strategic_merge(merged[item["name"]], item)
                                    if item["name"] in merged else item)
        return list(merged.values())
    return copy.deepcopy(patch)


def kustomize(directory):
    """The objects of a kustomization as `kubectl kustomize` renders these files: its resources
    (files or kustomization directories), then `replicas` and `patches` (strategic merge)."""
    kustomization = load_documents(directory / "kustomization.yaml")[0]
    documents = []
    for resource in kustomization.get("resources", []):
        path = directory / resource
        documents += kustomize(path) if path.is_dir() else copy.deepcopy(load_documents(path))
    for entry in kustomization.get("replicas", []):
        targets = [d for d in documents if d["metadata"]["name"] == entry["name"]
                   and d["kind"] in ("StatefulSet", "Deployment")]
        check(targets, f"{directory}: replicas for an unknown workload {entry['name']}")
        for target in targets:
            target["spec"]["replicas"] = entry["count"]
    for entry in kustomization.get("patches", []):
        for patch in load_documents(directory / entry["path"]):
            targets = [d for d in documents if d["kind"] == patch["kind"]
                       and d["metadata"]["name"] == patch["metadata"]["name"]]
            if check(len(targets) == 1, f"{directory}: patch {entry['path']} matches "
                                        f"{len(targets)} objects"):
                strategic_merge(targets[0], patch)
    return documents


def check_servers(objects, path):
    """The StatefulSet and its headless Service; returns the endpoints of its pods."""
    statefulset, service = objects["StatefulSet"][0], objects["Service"][0]
    spec, labels = statefulset["spec"], statefulset["spec"]["template"]["metadata"]["labels"]
    check(service["spec"].get("clusterIP") == "None", f"{path}: the Service is not headless")
    check(spec["serviceName"] == service["metadata"]["name"],
          f"{path}: serviceName {spec['serviceName']} is not the Service")
    for selector in (spec["selector"]["matchLabels"], service["spec"]["selector"]):
        check(selector.items() <= labels.items(), f"{path}: selector {selector} misses the pods")
    container = spec["template"]["spec"]["containers"][0]
    port = listen_port(container["args"])
    check(str(container["ports"][0]["containerPort"]) == port,
          f"{path}: containerPort is not the --listen port {port}")
    check(str(service["spec"]["ports"][0]["port"]) == port, f"{path}: Service port is not {port}")
    name = statefulset["metadata"]["name"]
    return [f"tcp://{name}-{index}.{spec['serviceName']}:{port}"
            for index in range(spec["replicas"])], labels


def shipped_file(source, key):
    """The shipped file a ConfigMap key holds: a case examples/KEY, a mesh examples/meshes/KEY."""
    return source / "examples" / key if key.endswith(".toml") else source / "examples/meshes" / key


def check_configmap(configmap, volume, source, path):
    """The ConfigMap holds shipped files verbatim; returns the paths mounted from it."""
    data = configmap["data"]
    for key, text in data.items():
        file = shipped_file(source, key)
        check(file.is_file() and text == file.read_text(),
              f"{path}: key {key} of ConfigMap {configmap['metadata']['name']} differs from "
              f"{file.relative_to(source)}")
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


def check_kubernetes_objects(documents, source, path):
    """The checks of one rendered kustomization; returns (servers, summary of the objects)."""
    objects = by_kind(documents)
    endpoints, server_labels = check_servers(objects, path)
    temporary_directories = check_temporary_directories(objects, path)
    job = objects["Job"][0]["spec"]["template"]
    container = job["spec"]["containers"][0]
    arguments = container["args"]
    connected = option_values(arguments, "--subdomain")
    check(connected == endpoints,
          f"{path}: the Job connects to {connected}, the StatefulSet's pods are {endpoints}")
    waited = job["spec"]["initContainers"][0]["command"][-1]
    for endpoint in endpoints:
        host = endpoint.split("//")[1].split(":")[0]
        check(re.search(re.escape(host) + r"\b", waited),
              f"{path}: the init container does not wait for {host}")
    volumes = {volume["name"]: volume for volume in job["spec"]["volumes"]}
    mounts = {mount["name"]: mount["mountPath"] for mount in container["volumeMounts"]}
    configmaps = {c["metadata"]["name"]: c for c in objects["ConfigMap"]}
    mounted_name = volumes["case"]["configMap"]["name"]
    check(mounted_name in configmaps, f"{path}: the Job mounts an undefined ConfigMap "
                                      f"{mounted_name}")
    configmap = configmaps[mounted_name]
    for other in configmaps.values():
        if other is not configmap:  # e.g. the base's case beside an overlay's: still verbatim
            check_configmap(other, {"configMap": {"name": other["metadata"]["name"],
                                                  "items": []}}, source, path)
    mounted = check_configmap(configmap, volumes["case"], source, path)
    case = arguments[0]
    check(case.startswith(mounts["case"] + "/") and case[len(mounts["case"]) + 1:] in mounted,
          f"{path}: case {case} is not mounted from the ConfigMap")
    case_text = configmap["data"][case.rsplit("/", 1)[1]]
    for line in case_text.splitlines():
        if line.startswith("mesh ="):
            mesh = line.split("=", 1)[1].strip().strip('"')
            check(mesh in mounted, f"{path}: mesh {mesh} of the case is not mounted")
    bodies = body_count(case_text)
    check(bodies == len(endpoints) == len(connected),
          f"{path}: the case {case} has {bodies} bodies, the StatefulSet {len(endpoints)} "
          f"replicas and the Job {len(connected)} endpoints: one server per body")
    claim = volumes["results"]["persistentVolumeClaim"]["claimName"]
    check(claim in [c["metadata"]["name"] for c in objects["PersistentVolumeClaim"]],
          f"{path}: claim {claim} is not defined")
    policy = objects["NetworkPolicy"][0]["spec"]
    check(policy["podSelector"]["matchLabels"].items() <= server_labels.items(),
          f"{path}: the NetworkPolicy does not select the servers")
    allowed = policy["ingress"][0]["from"][0]["podSelector"]["matchLabels"]
    check(allowed.items() <= job["metadata"]["labels"].items(),
          f"{path}: the NetworkPolicy does not admit the coordinator's pods")
    kinds = sorted(f"{document['kind']}/{document['metadata']['name']}" for document in documents)
    print(f"{path}: {len(documents)} objects; {bodies} bodies, Job -> {', '.join(connected)}; "
          f"{temporary_directories} read-only container(s) with an emptyDir at /tmp")
    return len(endpoints), kinds


KUSTOMIZATIONS = {".": 2, "four-bodies": 4}  # directory under deploy/kubernetes: its servers


def check_kubernetes(source):
    directory = source / "deploy/kubernetes"
    found = {str(path.parent.relative_to(directory))
             for path in directory.glob("**/kustomization.yaml")} - {"base"}
    check(found == set(KUSTOMIZATIONS), f"{directory}: kustomizations {sorted(found)}, this "
                                        f"script checks {sorted(KUSTOMIZATIONS)}")
    results = {}
    for name, servers in KUSTOMIZATIONS.items():
        path = directory / name
        count, kinds = check_kubernetes_objects(kustomize(path), source, path)
        check(count == servers, f"{path}: {count} servers, expected {servers}")
        results[name] = (count, kinds)
    return results


def check_rendered(source, name, file, own):
    """kubectl kustomize's output for the kustomization NAME: the same checks, and the same
    objects and replicas as this script's reading of it."""
    path = f"{file} (kubectl kustomize deploy/kubernetes/{name})"
    count, kinds = check_kubernetes_objects(load_documents(file), source, path)
    if name in own:
        check((count, kinds) == own[name],
              f"{path}: {count} servers and {kinds}; this script reads {own[name]}")


def main(arguments):
    if len(arguments) < 1 or len(arguments) % 3 != 1 or any(
            word != "--rendered" for word in arguments[1::3]):
        sys.exit(__doc__)
    source = pathlib.Path(arguments[0])
    own = {}
    for check_file in (check_compose, check_kubernetes):
        try:
            result = check_file(source)
            own = result if check_file is check_kubernetes else own
        except (KeyError, IndexError, TypeError, AttributeError, yaml.YAMLError) as error:
            problems.append(f"{check_file.__name__}: unexpected structure: {error!r}")
    for index in range(1, len(arguments), 3):
        name, file = arguments[index + 1], arguments[index + 2]
        try:
            check_rendered(source, name, file, own or {})
        except (KeyError, IndexError, TypeError, AttributeError, yaml.YAMLError) as error:
            problems.append(f"{file}: unexpected structure: {error!r}")
    for problem in problems:
        print("PROBLEM:", problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
