from setuptools import find_packages, setup

package_name = 'multilift_control'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='multilift developers',
    maintainer_email='dev@multilift.dev',
    description='Leader cascade controller and virtual-constraint follower nodes of multilift.',
    license='Apache-2.0',
    entry_points={
        # the parts multilift_sim's scenario validation finds (multilift_sim.parts)
        'multilift.parts': ['controllers = multilift_control.controllers'],
        'console_scripts': [
            'leader_node = multilift_control.ros.leader_node:main',
            'follower_node = multilift_control.ros.follower_node:main',
            'controllers_node = multilift_control.ros.controllers_node:main',
        ],
    },
)
